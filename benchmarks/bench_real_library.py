"""The library of real-situation queries (examples/queries/real/) over the 12 real sensor
recordings of ../shared/real_data (2 AV2 sensor logs, 10 nuScenes scenes); issue 16: "under 60 s
on 2 cores".

Two ways, as a user runs them:

* files: each query as ``scenegrep <kind> FILE RECORDINGS... <its Run options>`` does, in this
  process (``query_files``: read, label under the query's choice for unknown map layers, query);
* dataset: the recordings ingested once with 2 workers, labelled with unknown map layers taken as
  absent (``--unknown-layers strict``; nuScenes maps publish no crosswalks), its wall time
  reported apart; then each query as ``scenegrep <kind> FILE --dataset D --jobs 2``.

For each, the median over ``--repeat`` runs (after one warm-up run) of the whole library's wall
time, and per query its median; the number of matches per query (files and dataset must agree, or
the run stops).

    python benchmarks/bench_real_library.py [--repeat 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from scenegrep.dataset.files import query_files  # noqa: E402
from scenegrep.dataset.ingest import ingest  # noqa: E402
from scenegrep.dataset.run import RunOptions, run_query  # noqa: E402
from tests.library.catalog import SENSOR_RECORDINGS, LibraryQuery, library  # noqa: E402

REAL_DATA = REPO.parent / "shared" / "real_data"


def match_count(table) -> int:
    """Match rows of a results table (failed rows stop the benchmark)."""
    status = table.column("status").to_pylist()
    if "failed" in status:
        raise SystemExit(f"FAILED rows: {table.filter(table.column('status') == 'failed').to_pylist()[:1]}")
    return status.count("match")


def timed(run, query: LibraryQuery) -> tuple[float, int]:
    """Wall time (s) of ``run(query)`` and what it returns (a match count)."""
    start = time.perf_counter()
    count = run(query)
    return time.perf_counter() - start, count


def over_files(query: LibraryQuery, paths: list[str]) -> int:
    return match_count(query_files(paths, query.spec).table)


def over_dataset(query: LibraryQuery, root: Path) -> int:
    return match_count(run_query(root, query.spec, RunOptions(jobs=2)).table)


def measure(queries: list[LibraryQuery], run, repeat: int) -> tuple[list[float], dict[str, float], dict[str, int]]:
    """Whole-library wall times (s) of each repeat, per-query medians (s) and match counts."""
    per_query: dict[str, list[float]] = {q.name: [] for q in queries}
    counts: dict[str, int] = {}
    totals = []
    for attempt in range(repeat + 1):
        total = 0.0
        for query in queries:
            seconds, counts[query.name] = timed(run, query)
            total += seconds
            if attempt:
                per_query[query.name].append(seconds)
        if attempt:
            totals.append(total)
    return totals, {name: statistics.median(times) for name, times in per_query.items()}, counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args()
    queries = library()
    paths = [str(REAL_DATA / r) for r in SENSOR_RECORDINGS]
    print(f"{len(queries)} queries over {len(paths)} recordings, {args.repeat} repeats")
    files, files_each, files_counts = measure(queries, lambda q: over_files(q, paths), args.repeat)
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder) / "real"
        start = time.perf_counter()
        ingest(paths, root, jobs=2, unknown_layers="strict")
        ingest_s = time.perf_counter() - start
        data, data_each, data_counts = measure(queries, lambda q: over_dataset(q, root), args.repeat)
    if files_counts != data_counts:
        raise SystemExit(f"files and dataset disagree: {files_counts} != {data_counts}")
    print(f"{'query':48} {'files s':>8} {'dataset s':>9} {'matches':>7}")
    for query in queries:
        name = query.name
        print(f"{name:48} {files_each[name]:8.2f} {data_each[name]:9.2f} {files_counts[name]:7d}")
    print(f"library over files (1 process): median {statistics.median(files):.1f} s  (runs {files})")
    print(
        f"ingest (2 workers): {ingest_s:.1f} s; library over the dataset (2 workers): median "
        f"{statistics.median(data):.1f} s  (runs {data})"
    )
    if args.json:
        result = {
            "queries": len(queries),
            "recordings": len(paths),
            "files_s": files,
            "dataset_s": data,
            "ingest_s": ingest_s,
            "per_query": {
                n: {"files_s": files_each[n], "dataset_s": data_each[n], "matches": files_counts[n]} for n in files_each
            },
        }
        Path(args.json).write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
