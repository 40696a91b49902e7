"""``scenegrep label DATA... -o OUT``: behaviour labels from tracks and the road map.

Writes every input trace, with derived behaviour label sets (and confidences) and the lanes
found on the map, as ``OUT/<trace name>.parquet``; prints per-class label statistics on stdout
(``--json`` for a JSON document). The thresholds are those of ``--config`` (default: the
shipped, documented ``thresholds.toml``). A folder of traces is searched as the query commands
search it; over a folder or several paths an input that cannot be read or labelled is one
``scenegrep: failed:`` line on stderr and the others are written (exit code 3). One bad file
given alone is a user error (exit code 2).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from ..writers.file_names import file_stem
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
    parser.add_argument("--json", action="store_true", help="print the statistics as JSON")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_unknown_layers_argument(parser)
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from .. import readers
    from ..errors import UserError, at
    from ..label import label_trace, load_config
    from ..label.statistics import LabelStatistics
    from ..progress import bar
    from ..writers import write_trace_parquet

    if args.min_confidence is not None and not 0.0 <= args.min_confidence <= 1.0:
        raise UserError("--min-confidence must be between 0 and 1")
    config = load_config(args.config)
    fixed_map = readers.read_map(args.map) if args.map else None
    output = Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    statistics = LabelStatistics()
    choice = unknown_layers_of(args)
    names: set[str] = set()
    with bar(desc="labelling", unit=" traces", quiet=args.quiet, delay=0.5) as progress:

        def label_input(path: str) -> None:
            """Label and write every trace of one input."""
            for trace in readers.read_traces(path):
                road_map = fixed_map or (readers.read_map(trace.map_source) if trace.map_source else None)
                try:
                    labelled = label_trace(trace, road_map, config, args.min_confidence, choice).trace
                except UserError as exc:  # name the input where the labeller could not
                    raise exc if exc.location else UserError(exc.message, at(path)) from None
                write_trace_parquet(labelled, output / f"{_unique(trace.name, names)}.parquet")
                statistics.add(labelled)
                progress.update()

        code = each_input(args.data, label_input)
    text = json.dumps(statistics.as_dict(), indent=1) if args.json else statistics.table()
    sys.stdout.write(text + "\n")
    report_unknown_layers(choice)
    return code


def _unique(name: str, taken: set[str]) -> str:
    """A file-name-safe version of a trace name, distinct from those already ``taken``."""
    base = file_stem(name)
    candidate, k = base, 1
    while candidate in taken:
        k += 1
        candidate = f"{base}-{k}"
    taken.add(candidate)
    return candidate
