"""``scenegrep scene PROGRAM.scenic DATA...``: the labeled frames that are scenes of a Scenic program.

Output is one line per matching frame, ``NAME:FRAME-FRAME`` followed by the object
correspondence and the values of the program's random variables; ``--json``, ``--csv`` and
``--output`` give the results table (:mod:`.dataset_run`). ``--explain`` says, for a trace
without a match, why each frame does not match: the first features no correspondence satisfied.
Exit codes: 0 some frame matches, 1 none, 2 error, 3 some trace failed.
"""

from __future__ import annotations

import argparse
from typing import Any

from .dataset_run import run_query_command
from .options import (
    add_bag_arguments,
    add_dataset_arguments,
    add_map_argument,
    add_results_arguments,
    add_tolerance_arguments,
    add_unknown_layers_argument,
    scenic_query_options,
)


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "scene",
        help="find the labeled frames that are scenes of a Scenic program",
        description="Find the labeled frames that are instances of the static scene a Scenic program describes "
        "(seed 003): some injective correspondence of the program's objects to labeled objects, and some values "
        "of its random variables, reproduce the labeled positions, headings and explicit sizes within tolerance, "
        "and every require holds. DATA is any supported input (scenegrep traces, AV2, nuScenes, Waymo, "
        "CommonRoad, Scenic-generated scenes).",
    )
    parser.add_argument("program", metavar="PROGRAM", help="a .scenic file")
    parser.add_argument("data", nargs="*", metavar="DATA", help="labeled traces (files or recording directories)")
    add_map_argument(parser)
    add_tolerance_arguments(parser)
    add_unknown_layers_argument(parser)
    parser.add_argument("--exact", action="store_true", help="every labeled object in view must be matched")
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="ignore objects and map farther than M from the ego"
    )
    parser.add_argument(
        "--explain", action="store_true", help="for a trace without a match, say why each frame does not match"
    )
    parser.add_argument("--no-values", action="store_true", help="do not compute the random values of matches")
    parser.add_argument(
        "--json", action="store_true", help="print the results table as JSON Lines (one object per row)"
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    add_results_arguments(parser)
    add_dataset_arguments(parser)
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..scenic.parser import read_program

    options = {
        "visible_distance": args.visible_distance,
        "exact": args.exact,
        "explain": args.explain,
        "values": not args.no_values,
    }
    return run_query_command(
        args, "scene", read_program(args.program), args.program, options | scenic_query_options(args), args.data
    )
