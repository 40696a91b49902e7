"""``scenegrep label DATA... -o OUT``: behaviour labels from tracks and the road map.

Writes every input trace, with derived behaviour label sets (and confidences) and the lanes
found on the map, as ``OUT/<trace name>.parquet``; prints per-class label statistics on stdout
(``--json`` for one JSON Lines record). The thresholds are those of ``--config`` (default: the
shipped, documented ``thresholds.toml``). A folder of traces is searched as the query commands
search it; over a folder or several paths an input that cannot be read or labelled is one
``scenegrep: failed:`` line on stderr and the others are written (exit code 3). One bad file
given alone is a user error (exit code 2).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from .inputs import each_input
from .options import (
    add_bag_arguments,
    add_map_argument,
    add_unknown_layers_argument,
    report_unknown_layers,
    unknown_layers_of,
)


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "label",
        help="derive behaviour labels from tracks and the road map",
        description="Derive per-frame behaviour label sets (Stationary, FollowLane, LaneChangeLeft/Right, "
        "TurnLeft/Right, Brake, Accelerate, Reverse for vehicles; Stationary, Walk, Cross for pedestrians and "
        "cyclists) from tracks and the road map, with confidences, and write the labelled traces as Parquet.",
    )
    parser.add_argument("data", nargs="+", metavar="DATA", help="labeled traces (files or recording directories)")
    parser.add_argument("-o", "--output", required=True, metavar="OUT", help="directory for the labelled traces")
    add_map_argument(parser)
    parser.add_argument("--config", metavar="FILE", help="thresholds file (layout of the shipped thresholds.toml)")
    parser.add_argument(
        "--min-confidence", type=float, metavar="C", help="keep behaviours with confidence >= C (default from config)"
    )
    parser.add_argument("--json", action="store_true", help="print the statistics as JSON Lines (one object)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_unknown_layers_argument(parser)
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from .. import readers
    from ..label import load_config
    from ..label.files import FolderLabelling
    from ..progress import bar

    choice = unknown_layers_of(args)
    if args.map:
        readers.read_map(args.map)  # a bad --map is the user's error, before any trace is read
    labelling = FolderLabelling(Path(args.output), load_config(args.config), args.map, args.min_confidence, choice)
    with bar(desc="labelling", unit=" traces", quiet=args.quiet, delay=0.5) as progress:
        code = each_input(args.data, lambda path: labelling.label_input(path, progress.update))
    statistics = labelling.statistics
    if args.json:
        from ..json_lines import write

        write(statistics.as_dict())
    else:
        sys.stdout.write(statistics.table() + "\n")
    report_unknown_layers(choice)
    return code
