"""``scenegrep coverage`` end to end (issue 17): target under 10 s per run.

Two runs, each a fresh ``scenegrep coverage`` process (read the traces and maps, compile, match,
recover every match's values as intervals, bin them, write the coverage table as Parquet):

* the paper's Fig. 3 program (examples/scenes/fig3_car_ahead.scenic) over examples/sample (42
  traces), with the tolerances its comment suggests (1 m, 15 deg) and visible distance 50 m;
* a real-situation program, examples/queries/real/vehicle_in_same_lane_ahead_of_ego.scenic,
  over the nuScenes mini recordings (../shared/real_data/nuscenes_mini_scenarionet), with the
  options its ``# Run:`` line gives (--unknown-layers permissive).

For each, the median and min..max wall time over ``--repeat`` runs (and the median CPU time,
user + system: on a machine shared with other work the wall time grows, the CPU time hardly), the matches and variables
the coverage reports, and for comparison the median of the same query without coverage
(``scenegrep scene ... --no-values``: the part of the time that is the match itself).

    python benchmarks/bench_coverage.py [--repeat 3] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pyarrow.parquet as pq

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SCENEGREP_SHARED", REPO.parent / "shared"))
TARGET = 10.0

CASES = {
    "fig3 over examples/sample": (
        REPO / "examples" / "scenes" / "fig3_car_ahead.scenic",
        REPO / "examples" / "sample",
        ["--visible-distance", "50", "--tolerance-position", "1", "--tolerance-heading", "0.2618"],
    ),
    "vehicle_in_same_lane_ahead_of_ego over nuScenes mini": (
        REPO / "examples" / "queries" / "real" / "vehicle_in_same_lane_ahead_of_ego.scenic",
        SHARED / "real_data" / "nuscenes_mini_scenarionet",
        ["--unknown-layers", "permissive"],
    ),
}


def _seconds(argv: list[str]) -> tuple[float, float]:
    """(wall, CPU) seconds of one ``scenegrep`` process (CPU: user + system, which a machine
    shared with other work inflates far less than the wall time)."""
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "scenegrep", *argv], env=env, capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"scenegrep {' '.join(argv)} failed: {done.stderr.strip()}")
    return elapsed, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args()
    found = {}
    with tempfile.TemporaryDirectory() as tmp:
        table = Path(tmp) / "coverage.parquet"
        for name, (program, data, options) in CASES.items():
            if not data.exists():
                print(f"{name}: skipped ({data} is absent)")
                continue
            coverage = ["coverage", str(program), str(data), *options, "-q", "-o", str(table)]
            runs = [_seconds(coverage) for _ in range(args.repeat)]
            times, cpu = [w for w, _ in runs], [c for _, c in runs]
            plain = _seconds(["scene", str(program), str(data), *options, "--no-values", "-q"])
            rows = pq.read_table(table).to_pylist()
            singles = [r for r in rows if r["variable2"] is None and r["source"] is None]
            variables = list(dict.fromkeys(r["variable"] for r in singles))
            matched = max(sum(r["matches"] for r in singles if r["variable"] == v) for v in variables)
            median = statistics.median(times)
            found[name] = {
                "median_s": median,
                "min_s": min(times),
                "max_s": max(times),
                "median_cpu_s": statistics.median(cpu),
                "query_only_s": plain[0],
                "query_only_cpu_s": plain[1],
                "variables": len(variables),
                "matches_in_a_bin": matched,
                "verdict": "PASS" if median < TARGET else "FAIL",
            }
            print(
                f"{name}: median {median:.2f} s wall ({min(times):.2f}..{max(times):.2f}, {args.repeat} runs), "
                f"{statistics.median(cpu):.2f} s CPU; the query alone {plain[0]:.2f} s wall, {plain[1]:.2f} s CPU; "
                f"{len(variables)} axes, up to {matched} matches in bins; {found[name]['verdict']} "
                f"(target {TARGET:g} s wall)"
            )
    if args.json:
        Path(args.json).write_text(json.dumps(found, indent=2))


if __name__ == "__main__":
    main()
