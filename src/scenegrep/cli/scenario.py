"""``scenegrep scenario PROGRAM.scenic DATA... --window M``: windows a Scenic scenario's behaviours can produce.

Output is one line per match, ``SOURCE:FIRST-LAST`` (frame indices of the window)
and the object correspondence; with ``--all`` every correspondence and every
window start, else the first match per trace. ``--explain`` adds the witness of
each match (per step: labels, guard values, HFSM outputs and states) and, for a
trace without a match, the furthest frame reached and what failed there.
``--json`` prints one JSON object per line. When no trace matches, the nearest misses of the
initial scene at the window starts follow on stderr (:mod:`.misses`). Traces without behaviour labels are
labelled first (``scenegrep label``'s labeller, with a note on stderr).
``--online`` reads scenegrep JSON trace documents (one per line) from stdin and
reports each match as soon as its window is complete. Exit codes: 0 some trace
matches, 1 none, 2 error.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from .dataset_run import add_dataset_arguments, reject_dataset_only, run_dataset
from .scene import add_tolerance_arguments, tolerance_of, tolerance_options

NO_MATCH = 1


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
    add_tolerance_arguments(parser)
    parser.add_argument("--vocabulary", metavar="FILE", help="primitive behaviours -> dataset labels (TOML)")
    parser.add_argument(
        "--visible-distance", type=float, metavar="M", help="initial scene: ignore objects farther than M from the ego"
    )
    parser.add_argument("--all", action="store_true", help="every correspondence and window, not the first")
    parser.add_argument("--explain", action="store_true", help="explain matches and non-matches")
    parser.add_argument("--online", action="store_true", help="read trace documents from stdin, frame by frame")
    parser.add_argument("--json", action="store_true", help="print one JSON object per match")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    add_dataset_arguments(parser)
    parser.set_defaults(run=run)


def _records(result: Any, source: str, args: argparse.Namespace) -> list[dict[str, Any]]:
    trace = result.trace
    records = []
    for match, first, last in result.windows():
        record = {
            "source": source,
            "trace": trace.name,
            "match": True,
            "start_frame": int(trace.frame_index[first]),
            "end_frame": int(trace.frame_index[last]),
            "start_time": float(trace.frame_time[first]),
            "end_time": float(trace.frame_time[last]),
            "correspondence": match.correspondence,
        }
        if args.explain:
            record["explanation"] = result.explain(result.matches.index(match), first)
        records.append(record)
        if not args.all:
            break
    if not records and args.explain:
        records.append({"source": source, "trace": trace.name, "match": False, "failure": result.why_not()})
    return records


def _print(record: dict[str, Any], args: argparse.Namespace) -> None:
    if args.quiet:
        return
    if args.json:
        sys.stdout.write(json.dumps(record) + "\n")
        return
    if not record["match"]:
        sys.stdout.write(f"{record['source']}  no match: {record['failure']}\n")
        return
    pairs = "  ".join(f"{k}={v}" for k, v in record["correspondence"].items())
    sys.stdout.write(f"{record['source']}:{record['start_frame']}-{record['end_frame']}  {pairs}\n")
    for line in record.get("explanation", []):
        sys.stdout.write(f"    {line}\n")


def _options(args: argparse.Namespace) -> Any:
    from ..scenario import ScenarioOptions

    return ScenarioOptions(tolerance_of(args), args.visible_distance, args.all)


def _labelled(trace: Any, road_map: Any, args: argparse.Namespace) -> Any:
    if trace.behaviours is not None:
        return trace
    from ..label import label_trace

    if not args.quiet:
        print(f"scenegrep: note: {trace.name} has no behaviour labels; labelling it", file=sys.stderr)
    return label_trace(trace, road_map).trace


def _run_dataset(args: argparse.Namespace) -> int:
    from ..errors import UserError
    from ..scenic.parser import read_program

    if args.online:
        raise UserError("--online reads stdin; it does not take --dataset")
    options = {
        "window": args.window,
        "visible_distance": args.visible_distance,
        "vocabulary": args.vocabulary,
        "all": args.all,
        "explain": args.explain,
        **tolerance_options(args),
    }
    return run_dataset(args, "scenario", read_program(args.program), args.program, options)


def run(args: argparse.Namespace) -> int:
    from .. import readers
    from ..errors import UserError
    from ..scenario import load_scenario, load_vocabulary

    if args.dataset:
        return _run_dataset(args)
    reject_dataset_only(args)
    query = load_scenario(args.program, load_vocabulary(args.vocabulary), args.visible_distance)
    options = _options(args)
    road_map = readers.read_map(args.map) if args.map else None
    if args.online:
        if args.data:
            raise UserError("--online reads stdin; give no DATA")
        return _run_online(query, road_map, options, args)
    if not args.data:
        raise UserError("give DATA (trace files or directories), --dataset, or --online")
    from .misses import MissCollector, what_of

    found = False
    traces = matched = 0
    misses = MissCollector(what_of("scenario"))
    for path in args.data:
        many = readers.FORMATS[readers.detect_format(path)].many
        for trace in readers.read_traces(path):
            labelled = _labelled(trace, road_map, args)
            result = query.match(labelled, args.window, road_map, options)
            source = f"{path}#{trace.name}" if many else path
            for record in _records(result, source, args):
                _print(record, args)
            traces += 1
            matched += int(result.matched)
            found |= result.matched
            if not found:
                misses.offer(source, lambda t=labelled: query.initial_scene(t, args.window, road_map, options))
    if not args.quiet:
        print(f"scenegrep: {matched} of {traces} traces match", file=sys.stderr)
        if not found:
            misses.report(args.json)
    return 0 if found else NO_MATCH


def _run_online(query: Any, road_map: Any, options: Any, args: argparse.Namespace) -> int:
    from ..readers.trace_json import decode
    from ..scenario.online import OnlineScenario

    online = OnlineScenario(query, args.window, road_map, options)
    found = False
    for number, line in enumerate(sys.stdin.buffer, start=1):
        if not line.strip():
            continue
        chunk = _labelled(decode(line, f"<stdin>:{number}", "stdin"), road_map, args)
        for result in online.push(chunk):
            for record in _records(result, "<stdin>", args):
                _print(record, args)
                sys.stdout.flush()
            found |= result.matched
    return 0 if found else NO_MATCH
