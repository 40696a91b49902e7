"""``scenegrep report RESULTS -o report.html``: one page over a whole results table.

The page counts matches per trace, lists every match with a link to its view and draws charts
(matches per trace, window lengths, kinds of the corresponded objects, objects per kind); the
views of the matched traces go in ``<stem>_views/`` beside it. Exit codes: 0 written, 2 user error.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from .options import check_output_file
from ..wording import counted


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "report",
        help="an HTML report over a results table: counts, charts, every match opening its view",
        description="Write an HTML page over a results table (a --dataset run's results.parquet, --output, "
        "--json or --csv file, or its run directory): counts per trace, charts, and every match linked to the "
        "interactive view of its trace (written to <stem>_views/ beside the page).",
    )
    parser.add_argument("results", metavar="RESULTS", help="a results table or a run directory")
    parser.add_argument("-o", "--output", required=True, metavar="OUT", help="the .html file to write")
    parser.add_argument("--dataset", metavar="DATASET", help="the dataset of the results (default: where they lie)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..progress import bar
    from ..view.report import write_report
    from ..view.sources import ResultsSource

    check_output_file("-o", args.output, (".html",))
    source = ResultsSource.open(args.results, args.dataset)

    def progress(views: Any) -> Any:
        return bar(views, args.quiet, unit="view", leave=False)

    written = write_report(source, args.output, progress)
    if not args.quiet:
        matches = source.results.matches.num_rows
        views = counted(written, "trace view")
        print(f"scenegrep: report of {counted(matches, 'match')} in {args.output} ({views})", file=sys.stderr)
    return 0
