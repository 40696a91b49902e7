"""``scenegrep scenario PROGRAM.scenic DATA... --window M``: windows a Scenic scenario's behaviours can produce.

Output is one line per match, ``NAME:FIRST-LAST`` (dataset frame indices of the window's
first and last frame) and the object correspondence; with ``--all`` every correspondence and
every window start, else the first match per trace. ``--explain`` adds the witness of each match
(per step: labels, guard values, HFSM outputs and states) and, for a trace without a match, the
furthest frame reached and what failed there. ``--json``, ``--csv`` and ``--output`` give the
results table (:mod:`.dataset_run`). Traces without behaviour labels are labelled first with
their own road map, as ``ingest`` labels them. ``--online`` reads scenegrep JSON trace documents
(one per line) or an MCAP stream from stdin, ``--follow FILE`` an MCAP file as it is written
(:mod:`.live`), and reports each match as soon as its window is complete
(:class:`scenegrep.streams.scenario.ScenarioStream`); the program objects whose kinds no frame had
are warned about once the stream has ended. Exit codes:
0 some trace matches, 1 none, 2 error, 3 some trace failed.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from .dataset_run import RowPrinter, print_warnings, run_query_command
from .exit_codes import EXIT_NO_MATCH
from .options import (
    add_bag_arguments,
    add_dataset_arguments,
    add_live_arguments,
    add_map_argument,
    add_results_arguments,
    add_tolerance_arguments,
    add_unknown_layers_argument,
    check_live_arguments,
    reject_dataset_only,
    report_unknown_layers,
    scenic_query_options,
    tolerance_of,
    unknown_layers_of,
)


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "scenario",
        help="find the windows of label traces that a Scenic scenario's behaviours can produce",
        description="Find windows of m consecutive frames whose first frame is a scene of the program (seed 003) "
        "and whose behaviour labels the program's behaviours, compiled to hierarchical state machines, can "
        "produce under some object correspondence (seed 000).",
    )
    parser.add_argument("program", metavar="PROGRAM", help="a .scenic file")
    parser.add_argument("data", nargs="*", metavar="DATA", help="labeled traces (files or recording directories)")
    parser.add_argument(
        "--window", required=True, metavar="M", help="window length: frames (50), seconds (5s) or 'all'"
    )
    add_map_argument(parser)
    add_tolerance_arguments(parser)
    add_unknown_layers_argument(parser)
    parser.add_argument("--vocabulary", metavar="FILE", help="primitive behaviours -> dataset labels (TOML)")
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="initial scene: ignore objects farther than M from the ego"
    )
    parser.add_argument("--all", action="store_true", help="every correspondence and window, not the first")
    parser.add_argument("--explain", action="store_true", help="explain matches and non-matches")
    parser.add_argument(
        "--online",
        action="store_true",
        help="read trace documents or an MCAP stream from stdin, frame by frame; unlabelled frames get the offline "
        "labels, a fixed delay later (3.5 s at 10 Hz, said on stderr)",
    )
    add_live_arguments(parser)
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

    check_live_arguments(args)
    if args.online or args.follow:
        return _run_online(args)
    options = {
        "window": args.window,
        "visible_distance": args.visible_distance,
        "vocabulary": args.vocabulary,
        "all": args.all,
        "explain": args.explain,
        **scenic_query_options(args),
    }
    return run_query_command(args, "scenario", read_program(args.program), args.program, options, args.data)


def _run_online(args: argparse.Namespace) -> int:
    """``--online``: trace documents or MCAP messages from stdin, or ``--follow FILE``; each match
    printed as its window completes; the program objects no frame could be are said at the end."""
    from .. import readers
    from ..errors import UserError
    from ..scenario import ScenarioOptions, load_scenario, load_vocabulary
    from ..streams.live import trace_documents
    from ..streams.scenario import ScenarioStream
    from .live import open_input, report, until_stopped

    if args.data or args.dataset:
        raise UserError("--online reads stdin or --follow FILE; give no DATA or --dataset")
    reject_dataset_only(args)
    query = load_scenario(args.program, load_vocabulary(args.vocabulary), args.visible_distance)
    road_map = readers.read_map(args.map) if args.map else None
    choice = unknown_layers_of(args)
    options = ScenarioOptions(tolerance_of(args), args.visible_distance, args.all, unknown_layers=choice)
    live = open_input(args, trace_documents)
    stream = ScenarioStream(query, args.window, road_map, options, live.source, args.all, args.explain)
    printer = RowPrinter(args)

    def announce(delay: str) -> None:
        if not args.quiet:
            print(f"scenegrep: {delay}", file=sys.stderr)

    def show(results: list[Any]) -> None:
        for result in live.latency.each_match(results):
            printer(stream.rows(result))

    with until_stopped():
        for results in stream.results(live.chunks, announce):
            show(results)
    show(stream.final())
    print_warnings(stream.warnings, args)
    for note in stream.notes:
        print(f"scenegrep: {note}", file=sys.stderr)
    report_unknown_layers(choice)
    report(live.latency, args)
    return 0 if live.latency.found else EXIT_NO_MATCH
