"""``--dataset DATASET``: the options and output the query commands share when they run over a
dataset (through :mod:`scenegrep.dataset`).

Output: one line per match ``NAME:START-END  correspondence`` (dataset frame indices of the
window's first and last frame), or the whole results table with ``--json`` (one object per
row) or ``--csv``; a summary and the pruning on stderr. Exit codes: 0 some trace matches,
1 none, 2 user error, 3 some trace failed (its error is in the results), 130 interrupted
(the results so far are kept; ``--resume`` continues).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from typing import Any

from .main import EXIT_INTERRUPTED, EXIT_SOME_FAILED

NO_MATCH = 1


def add_dataset_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of a run over a dataset."""
    group = parser.add_argument_group("datasets (scenegrep ingest)")
    group.add_argument("--dataset", metavar="DATASET", help="query every trace of an ingested dataset")
    group.add_argument("-j", "--jobs", type=int, metavar="N", help="worker processes (default: all cores)")
    group.add_argument("--engine", choices=["local", "ray"], default="local", help="local processes or Ray")
    group.add_argument("--address", metavar="ADDR", help="Ray cluster address (default: start a local Ray)")
    group.add_argument("--resume", action="store_true", help="continue an interrupted run of the same query")
    group.add_argument("--output", metavar="FILE", help="also write the results table to this Parquet file")
    group.add_argument("--csv", action="store_true", help="print the results table as CSV")


def reject_dataset_only(args: argparse.Namespace) -> None:
    """Dataset options given without --dataset are user errors."""
    from ..errors import UserError

    for name in ("resume", "output", "csv"):
        if getattr(args, name):
            raise UserError(f"--{name} needs --dataset")
    if args.engine != "local" or args.jobs is not None or args.address:
        raise UserError("--jobs, --engine and --address need --dataset")


def run_dataset(args: argparse.Namespace, kind: str, query: str, origin: str, options: dict[str, Any]) -> int:
    """Run a query over ``args.dataset`` and print its results; returns the exit code."""
    from pathlib import Path

    from ..dataset import QuerySpec
    from ..dataset.run import RunOptions, run_query
    from ..errors import UserError

    if getattr(args, "data", None):
        raise UserError("give either DATA paths or --dataset, not both")
    spec = QuerySpec.of(kind, query, origin, **options)
    quiet = args.quiet
    run = RunOptions(
        args.jobs, args.engine, args.address, args.resume, getattr(args, "map", None), not quiet and sys.stderr.isatty()
    )
    results = run_query(Path(args.dataset).resolve(), spec, run, on_plan=None if quiet else _report_plan)
    if args.output:
        results.write_parquet(args.output)
    if not quiet:
        _print(results, args)
        _summary(results, Path(args.dataset))
        if kind != "spre" and not results.counts()["matched"]:
            _misses(spec, results, Path(args.dataset).resolve(), args)
    counts = results.counts()
    if results.status == "interrupted":
        return EXIT_INTERRUPTED
    if counts["failed"]:
        return EXIT_SOME_FAILED
    return 0 if counts["matched"] else NO_MATCH


def _misses(spec: Any, results: Any, root: Any, args: argparse.Namespace) -> None:
    """The nearest misses of a Scenic query that matched nothing in the dataset at ``root``."""
    from ..dataset.misses import nearest_misses
    from ..view.sources import load_trace
    from .misses import print_misses, what_of

    misses = nearest_misses(spec, results.table.to_pylist(), lambda trace_id: load_trace(root, trace_id))
    print_misses(misses, what_of(spec.kind), args.json)


def _report_plan(plan: Any) -> None:
    total = len(plan.kept) + len(plan.pruned)
    print(f"scenegrep: querying {len(plan.kept)} of {total} traces", file=sys.stderr)
    for reason, count in Counter(_general(r) for _, r in plan.pruned).most_common():
        print(f"scenegrep: pruned {count}: {reason}", file=sys.stderr)


def _general(reason: str) -> str:
    """A pruning reason without the trace's own numbers (so reasons group)."""
    return reason.split(" (at most")[0]


def _print(results: Any, args: argparse.Namespace) -> None:
    out = sys.stdout
    if args.json:
        results.write_json(out)
        return
    if args.csv:
        results.write_csv(out)
        return
    for row in results.matches.to_pylist():
        pairs = "  ".join(f"{k}={v}" for k, v in json.loads(row["correspondence"] or "{}").items())
        out.write(f"{row['name']}:{row['start_frame']}-{row['end_frame']}  {pairs}".rstrip() + "\n")
        for line in (row["explanation"] or "").splitlines() if getattr(args, "explain", False) else ():
            out.write(f"    {line}\n")


def _summary(results: Any, dataset: Any) -> None:
    counts = results.counts()
    for row in results.failed.to_pylist():
        print(f"scenegrep: failed: {row['name']}: {row['error']}", file=sys.stderr)
    state = " (interrupted: continue with --resume)" if results.status == "interrupted" else ""
    print(
        f"scenegrep: {counts['matched']} of {counts['traces']} traces match, {counts['pruned']} pruned, "
        f"{counts['failed']} failed{state}; results in {dataset / 'runs' / results.run_id / 'results.parquet'} "
        f"and the catalog (SELECT * FROM results WHERE run_id = '{results.run_id}')",
        file=sys.stderr,
    )
