"""``scenegrep export RESULTS --mcap OUT.mcap``: a results table's matches as Foxglove events.

RESULTS is a results Parquet file (``DATASET/runs/RUN/results.parquet`` or a run's
``--output``) or a run directory. Exit codes: 0 written, 2 user error.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "export",
        help="write a results table's matches for other viewers (Foxglove MCAP events)",
        description="Write the matches of a results table as Foxglove events (schema foxglove.Event, topic "
        "/scenegrep/matches) in an MCAP file: each event spans the window's first to last frame at the "
        "recording's absolute time, with the trace and the correspondence as metadata.",
    )
    parser.add_argument("results", metavar="RESULTS", help="a results .parquet file or a run directory")
    parser.add_argument("--mcap", required=True, metavar="OUT", help="the MCAP file to write")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dataset.export import write_mcap_events
    from ..dataset.results import Results

    count = write_mcap_events(Results.read(args.results), args.mcap)
    if not args.quiet:
        print(f"scenegrep: {count} matches written as Foxglove events to {args.mcap}", file=sys.stderr)
    return 0
