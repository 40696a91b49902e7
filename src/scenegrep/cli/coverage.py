"""``scenegrep coverage PROGRAM DATA... | --dataset D``: how much of a program's parameter space the data covers.

The program is queried as ``scene`` queries it (with ``--window``, as ``scenario`` does, every
window, and the coverage is that of the windows' initial scenes), on the same engine over files
or over a dataset. For every match, the values of each random variable that reproduce its
(first) frame are recovered as intervals, binned over the variable's declared domain
(:mod:`scenegrep.dataset.coverage`). Output: a text summary on stdout (per variable the matches
per bin, the gaps and the ambiguous matches, the joint coverage of pairs, per source);
``--output`` the coverage table (Parquet or JSON); ``--html`` a page of the plots whose bins
link to their matches' views; ``--png`` the plots as one picture (:mod:`scenegrep.view.coverage_png`).
Exit codes: 0 some match, 1 none, 2 error, 3 some trace failed.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from .dataset_run import RowPrinter, results_of
from .exit_codes import EXIT_INTERRUPTED, EXIT_NO_MATCH, EXIT_SOME_FAILED
from .options import (
    add_dataset_arguments,
    add_map_argument,
    add_tolerance_arguments,
    add_unknown_layers_argument,
    check_output_file,
    scenic_query_options,
)

DEFAULT_BINS = 10


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "coverage",
        help="which values of a Scenic program's random variables the data's matches show, and the gaps",
        description="Query the data with a Scenic scene program (with --window: a scenario program's initial "
        "scene at every matching window) and report, per random variable (Range, Normal, TruncatedNormal, Options, "
        "random points), the values that reproduce the matches binned over its declared domain: bins covered, "
        "gaps, ambiguous matches (several values reproduce the frame across a bin edge), joint coverage of pairs "
        "of variables, and all that per source.",
    )
    parser.add_argument("program", metavar="PROGRAM", help="a .scenic file")
    parser.add_argument("data", nargs="*", metavar="DATA", help="labeled traces (files or recording directories)")
    add_map_argument(parser)
    add_tolerance_arguments(parser)
    add_unknown_layers_argument(parser)
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="ignore objects and map farther than M from the ego"
    )
    parser.add_argument("--window", metavar="M", help="a scenario program: windows of M frames, seconds (5s) or 'all'")
    parser.add_argument(
        "--bins", type=int, default=DEFAULT_BINS, metavar="N", help=f"bins per variable (default {DEFAULT_BINS})"
    )
    parser.add_argument("-o", "--output", metavar="FILE", help="write the coverage table (.parquet or .json)")
    parser.add_argument("--html", metavar="PAGE", help="write the page of plots (.html) and the matches' views")
    parser.add_argument("--png", metavar="FILE", help="write the plots as one picture (.png)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    add_dataset_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dataset import QuerySpec
    from ..dataset.coverage import checked_bins, coverage_of, unknown_data, variables_of
    from ..dataset.coverage_text import summary_text
    from ..scenic.parser import read_program

    bins = checked_bins(args.bins)
    for option, path, suffixes in (
        ("--output", args.output, (".parquet", ".json")),
        ("--html", args.html, (".html",)),
        ("--png", args.png, (".png",)),
    ):
        if path is not None:
            check_output_file(option, path, suffixes)
    options: dict[str, Any] = {
        "visible_distance": args.visible_distance,
        "intervals": True,
        **scenic_query_options(args),
    }
    if args.window is not None:
        options |= {"window": args.window, "all": True}
    kind = "scene" if args.window is None else "scenario"
    spec = QuerySpec.of(kind, read_program(args.program), args.program, **options)
    results, _ = results_of(args, spec, args.data, RowPrinter(args, failures_only=True))
    coverage = coverage_of(results.matches.to_pylist(), variables_of(spec), bins, unknown_data(results))
    if args.output:
        coverage.write(args.output)
    if args.html:
        from ..view.coverage_page import write_coverage_page
        from ..view.sources import ResultsSource

        root = Path(args.dataset).resolve() if args.dataset else None
        write_coverage_page(ResultsSource.of_results(results, root), coverage, args.html)
    if args.png:
        from ..view.coverage_png import write_coverage_png

        write_coverage_png(coverage, args.png)
    if not args.quiet:
        print(summary_text(coverage, args.program))
    counts = results.counts()
    if results.status == "interrupted":
        return EXIT_INTERRUPTED
    if counts["failed"]:
        return EXIT_SOME_FAILED
    return 0 if counts["matched"] else EXIT_NO_MATCH
