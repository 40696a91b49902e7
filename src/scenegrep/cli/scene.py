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

from .bag_options import add_arguments as add_bag_arguments
from .dataset_run import add_dataset_arguments, run_query_command
from .layers import add_unknown_layers_argument


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
    add_tolerance_arguments(parser)
    parser.add_argument("--exact", action="store_true", help="every labeled object in view must be matched")
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="ignore objects and map farther than M from the ego"
    )
    parser.add_argument(
        "--explain", action="store_true", help="for a trace without a match, say why each frame does not match"
    )
    parser.add_argument("--no-values", action="store_true", help="do not compute the random values of matches")
    parser.add_argument("--json", action="store_true", help="print the results table as JSON lines")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    add_dataset_arguments(parser)
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def add_tolerance_arguments(parser: argparse.ArgumentParser) -> None:
    """``--map`` and the scene tolerances, shared by the Scenic query commands."""
    from ..scene.profiles import PROFILES

    parser.add_argument(
        "--map", metavar="MAP", help="road map for traces without one (e.g. an .xodr or a Lanelet2 .osm file)"
    )
    parser.add_argument(
        "--tolerance-profile",
        metavar="NAME",
        help=f"tolerances measured on a dataset's labels ({', '.join(PROFILES)}; default exact); "
        "--tolerance-position, --tolerance-heading and --tolerance-speed override its values",
    )
    parser.add_argument(
        "--tolerance-position", type=float, metavar="M", help="position and size tolerance (m; default 1e-6)"
    )
    parser.add_argument("--tolerance-heading", type=float, metavar="RAD", help="heading tolerance (rad; default 1e-6)")
    parser.add_argument(
        "--tolerance-speed", type=float, metavar="M/S", help="speed and velocity tolerance (m/s; default 1e-6)"
    )
    add_unknown_layers_argument(parser)


def tolerance_of(args: argparse.Namespace) -> Any:
    """The :class:`~scenegrep.scene.Tolerance` the options give: the profile's, each given tolerance
    instead of its value (unknown profiles and negative values are user errors)."""
    from ..scene.profiles import tolerance_of

    return tolerance_of(
        args.tolerance_profile,
        position=args.tolerance_position,
        heading=args.tolerance_heading,
        speed=args.tolerance_speed,
    )


def tolerance_options(args: argparse.Namespace) -> dict[str, Any]:
    """The tolerance options as dataset query options (checked)."""
    tolerance_of(args)
    return {
        "tolerance_profile": args.tolerance_profile,
        "tolerance_position": args.tolerance_position,
        "tolerance_heading": args.tolerance_heading,
        "tolerance_speed": args.tolerance_speed,
        "unknown_layers": args.unknown_layers,
    }


def run(args: argparse.Namespace) -> int:
    from ..scenic.parser import read_program

    options = {
        "visible_distance": args.visible_distance,
        "exact": args.exact,
        "explain": args.explain,
        "values": not args.no_values,
    }
    return run_query_command(
        args, "scene", read_program(args.program), args.program, options | tolerance_options(args), args.data
    )
