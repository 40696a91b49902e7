"""``scenegrep spre PATTERN [FILE...]``: Spatial Regular Expression matching, offline and online.

Output is one line per match, ``PATH:START..END`` (frame indices, half-open; no path for
standard input), or with ``--json`` one JSON object per match. Exit codes: 0 some match,
1 none, 2 error.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from .dataset_run import add_dataset_arguments, reject_dataset_only, run_dataset

NO_MATCH = 1


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "spre",
        help="match a Spatial Regular Expression over perception streams",
        description="Find the stretches of frames that match a Spatial Regular Expression (seed 004). "
        "Offline: all non-overlapping leftmost-longest matches; --online: after each frame, the longest match "
        "ending there. FILE is any supported input (STREM JSON, scenegrep traces, AV2, nuScenes, Waymo, "
        "CommonRoad); none or - reads STREM JSON documents from standard input.",
    )
    parser.add_argument("pattern", metavar="PATTERN", help="the SpRE, e.g. '[[:car:]]{2,}[[:pedestrian:]]'")
    parser.add_argument("files", nargs="*", metavar="FILE", help="inputs (default: standard input)")
    parser.add_argument(
        "-c", "--channel", action="append", metavar="NAME", help="keep only this image channel (repeatable)"
    )
    parser.add_argument("-o", "--online", action="store_true", help="online matching: a match per incoming frame")
    parser.add_argument("-m", "--max-count", type=int, metavar="NUM", help="print at most NUM matches per file")
    parser.add_argument("-x", "--export", action="store_true", help="print each match's frames as one-line JSON")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    parser.add_argument(
        "-s", "--skip", type=int, default=0, metavar="NUM", help="drop the first NUM frames of each file"
    )
    parser.add_argument("--json", action="store_true", help="print each match as a JSON object")
    parser.add_argument("--compat", choices=["strem"], help="STREM v0.2.0's syntax and precedence")
    parser.add_argument(
        "--space",
        choices=["image", "topdown"],
        help="search image boxes or top-down object boxes (default: image if the input has any)",
    )
    add_dataset_arguments(parser)
    parser.set_defaults(run=run)


def _export(match: Any, trace: Any, options: Any) -> dict[str, Any]:
    """The matched frames: a STREM JSON document for image detections, else a scenegrep JSON trace."""
    if trace.images is not None and options.space != "topdown":
        from ..writers.strem_json import strem_document

        return strem_document(trace, match.start, match.end, options.channels)
    from ..writers.trace_json import trace_document

    return trace_document(trace.slice_frames(match.start, match.end))


def _line(match: Any, prefix: str, args: argparse.Namespace, trace: Any, options: Any) -> str:
    start, end = match.index_range
    if args.json:
        record: dict[str, Any] = {
            "source": prefix or "<stdin>",
            "start": start,
            "end": end,
            "start_time": match.start_time,
            "end_time": match.end_time,
        }
        if trace is not None:
            record["trace"] = trace.name
            record["frames"] = trace.frame_index[match.start : match.end].tolist()
        if match.bound:
            record["bound"] = match.bound
        return json.dumps(record, allow_nan=True)
    if args.export and trace is not None:
        return json.dumps(_export(match, trace, options), separators=(",", ":"), allow_nan=True)
    return f"{prefix}:{start}..{end}" if prefix else f"{start}..{end}"


def _report(matches: Any, prefix: str, args: argparse.Namespace, options: Any, trace: Any = None) -> bool:
    """Print the matches of one file (at most --max-count); True when there was any."""
    found = False
    printed = 0
    out = sys.stdout
    for match in matches:
        found = True
        if args.quiet or (args.max_count is not None and printed >= args.max_count):
            if not args.online:
                break
            continue
        out.write(_line(match, prefix, args, trace, options) + "\n")
        printed += 1
        if args.online:
            out.flush()
    return found


def _run_dataset(args: argparse.Namespace) -> int:
    from ..errors import UserError

    if args.online or args.export or args.max_count is not None:
        raise UserError("--online, --export and --max-count read files; with --dataset use the results table")
    options = {
        "compat": args.compat == "strem",
        "space": args.space,
        "channels": tuple(args.channel) if args.channel else None,
        "skip": args.skip,
    }
    return run_dataset(args, "spre", args.pattern, "<query>", options)


def run(args: argparse.Namespace) -> int:
    from .. import readers
    from ..readers.strem_json import iter_documents
    from ..spre import SearchOptions, TraceSearch, compile_query, search_stream

    if args.dataset:
        return _run_dataset(args)
    reject_dataset_only(args)
    query = compile_query(args.pattern, compat=args.compat == "strem")
    for warning in query.warnings:
        print(f"scenegrep: warning: {warning}", file=sys.stderr)
    options = SearchOptions(args.space, tuple(args.channel) if args.channel else None, max(args.skip, 0))
    found = False
    for path in args.files or ["-"]:
        if path == "-" and args.online:
            found |= _report(search_stream(query, iter_documents(sys.stdin.buffer), options), "", args, options)
            continue
        many = path != "-" and readers.FORMATS[readers.detect_format(path)].many
        for trace in readers.read_traces(path):
            bound = TraceSearch(query, trace, options)
            matches = bound.online() if args.online else bound.offline()
            prefix = "" if path == "-" else f"{path}#{trace.name}" if many else path
            found |= _report(matches, prefix, args, options, bound.trace)
    return 0 if found else NO_MATCH
