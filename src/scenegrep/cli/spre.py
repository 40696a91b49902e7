"""``scenegrep spre PATTERN [FILE...]``: Spatial Regular Expression matching, offline and online.

Over files, the dataset engine's query (:mod:`.dataset_run`): one line per match,
``SOURCE#NAME:START-END`` (:mod:`scenegrep.dataset.places`: the path as given, the trace's name,
dataset frame indices of the first and last frame), or the results table with ``--json``,
``--csv`` or ``--output``; a bad file is a failed row (exit code 3), or given alone a user error
(exit code 2). As STREM does (``--compat strem``, ``--online``, ``--export``, standard input):
each stream searched as it is read, with the same lines (``-`` the source of standard input; a
live stream, ``--online`` over standard input or ``--follow``, has no trace name:
``SOURCE:START-END``), or STREM's ``PATH:START..END`` (first index .. last index + 1;
``PATH#NAME`` for a file of several traces, no path for standard input) with ``--compat
strem``; the first bad input ends the command (exit code 2). Exit codes: 0 some match, 1 none,
2 error, 3 some file failed.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ..json_lines import line
from .dataset_run import run_query_command
from .exit_codes import EXIT_NO_MATCH
from .options import (
    add_bag_arguments,
    add_dataset_arguments,
    add_live_arguments,
    add_results_arguments,
    check_live_arguments,
    reject_dataset_only,
)


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
    parser.add_argument("--online", action="store_true", help="online matching: a match per incoming frame")
    parser.add_argument("-m", "--max-count", type=int, metavar="NUM", help="print at most NUM matches per file")
    parser.add_argument("-x", "--export", action="store_true", help="print each match's frames as one-line JSON")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit code tells")
    parser.add_argument(
        "-s", "--skip", type=int, default=0, metavar="NUM", help="drop the first NUM frames of each file"
    )
    parser.add_argument(
        "--json", action="store_true", help="print JSON Lines: one object per results row (per match over streams)"
    )
    parser.add_argument("--compat", choices=["strem"], help="STREM v0.2.0's syntax and precedence")
    parser.add_argument(
        "--space",
        choices=["image", "topdown"],
        help="search image boxes or top-down object boxes (default: image if the input has any)",
    )
    add_live_arguments(parser)
    add_results_arguments(parser)
    add_dataset_arguments(parser)
    add_bag_arguments(parser)
    parser.set_defaults(run=run)


def _export(match: Any, trace: Any, options: Any) -> dict[str, Any]:
    """The matched frames: a STREM JSON document for image detections, else a scenegrep JSON trace."""
    if trace.images is not None and options.space != "topdown":
        from ..writers.strem_json import strem_document

        return strem_document(trace, match.start, match.end, options.channels)
    from ..writers.trace_json import trace_document

    return trace_document(trace.slice_frames(match.start, match.end))


def _line(match: Any, source: str, prefix: str, args: argparse.Namespace, trace: Any, options: Any) -> str:
    """One match as text (``SOURCE#NAME:START-END``, ``SOURCE:START-END`` for a live stream
    without a ``trace``; with ``--compat strem`` STREM's ``PREFIX:START..END``), a JSON Lines
    record (``source``: the path as given, ``-`` for standard input) or, with ``--export``, the
    matched frames."""
    if args.json:
        record: dict[str, Any] = {
            "source": source,
            "start_frame": match.first_index,
            "end_frame": match.last_index,
            "start_time": match.start_time,
            "end_time": match.end_time,
        }
        if trace is not None:
            record["trace"] = trace.name
        if match.bound:
            record["bound"] = match.bound
        return line(record)
    if args.export and trace is not None:
        return json.dumps(_export(match, trace, options), separators=(",", ":"), allow_nan=True)
    if args.compat == "strem":
        span = "{}..{}".format(*match.index_range)
        return f"{prefix}:{span}" if prefix else span
    from ..dataset.places import place

    if trace is None:
        return f"{source}:{match.first_index}-{match.last_index}"
    return place(source, trace.name, match.first_index, match.last_index)


def _report(matches: Any, source: str, prefix: str, args: argparse.Namespace, options: Any, trace: Any = None) -> bool:
    """Print the matches of one file, ``source`` (its path as given, ``-`` for standard input),
    of its ``trace`` (None for a live stream), at most --max-count, with ``--compat strem`` each
    line starting with STREM's ``prefix``; True when there was any."""
    found = False
    printed = 0
    out = sys.stdout
    for match in matches:
        found = True
        if args.quiet or (args.max_count is not None and printed >= args.max_count):
            if not args.online:
                break
            continue
        out.write(_line(match, source, prefix, args, trace, options) + "\n")
        printed += 1
        if args.online:
            out.flush()
    return found


def _streams(args: argparse.Namespace) -> bool:
    """Whether the command searches streams as STREM does (``--compat strem``, ``--online``,
    ``--export`` or standard input), printing each file's matches as found and stopping at the
    first bad input, rather than running the dataset engine's query over files."""
    return args.compat == "strem" or args.online or args.export or not args.files or "-" in args.files


def run(args: argparse.Namespace) -> int:
    from ..errors import UserError

    check_live_arguments(args)
    if args.follow:
        if args.files or args.dataset:
            raise UserError("--follow FILE reads that file; give no other FILE or --dataset")
        args.online = True
    if not args.dataset and _streams(args):
        reject_dataset_only(args)
        if args.output or args.csv:
            raise UserError("--output and --csv give the results table: not with --compat, --online, --export or stdin")
        return _run_streams(args)
    if args.online or args.export:
        raise UserError("--online and --export read files; with --dataset use the results table")
    options = {
        "compat": args.compat == "strem",
        "space": args.space,
        "channels": tuple(args.channel) if args.channel else None,
        "skip": args.skip,
    }
    return run_query_command(args, "spre", args.pattern, "<query>", options, args.files)


def _run_streams(args: argparse.Namespace) -> int:
    from .. import readers
    from ..spre import SearchOptions, TraceSearch, compile_query

    query = compile_query(args.pattern, compat=args.compat == "strem")
    for warning in query.warnings:
        print(f"scenegrep: warning: {warning}", file=sys.stderr)
    options = SearchOptions(args.space, tuple(args.channel) if args.channel else None, max(args.skip, 0))
    if args.follow:
        return _run_live(query, args, options)
    found = False
    for path in args.files or ["-"]:
        if path == "-" and args.online:
            found |= _run_live(query, args, options) == 0
            continue
        many = path != "-" and readers.FORMATS[readers.detect_format(path)].many
        for trace in readers.read_traces(path):
            bound = TraceSearch(query, trace, options)
            for warning in [] if args.quiet else bound.warnings:
                print(f"scenegrep: warning: {path if path != '-' else '<stdin>'}: {warning}", file=sys.stderr)
            matches = bound.online() if args.online else bound.offline()
            prefix = "" if path == "-" else f"{path}#{trace.name}" if many else path
            found |= _report(matches, path, prefix, args, options, bound.trace)
    return 0 if found else EXIT_NO_MATCH


def _run_live(query: Any, args: argparse.Namespace, options: Any) -> int:
    """Online matching of a live input: ``--follow FILE``, or standard input (MCAP or STREM JSON)."""
    import time

    from ..readers.strem_json import iter_documents
    from ..spre import search_stream
    from .live import Latency, mcap_chunks, report, standard_input, until_stopped

    if args.follow:
        chunks, latency = mcap_chunks(args.follow, args)
    else:
        is_mcap, stdin = standard_input()
        if is_mcap:
            chunks, latency = mcap_chunks("-", args, stdin)
        else:
            latency = Latency(time.perf_counter, args.latency)
            chunks = latency.chunks(iter_documents(stdin))
    with until_stopped():
        source = args.follow or "-"
        _report(latency.each_match(search_stream(query, chunks, options)), source, args.follow or "", args, options)
    report(latency, args)
    return 0 if latency.found else EXIT_NO_MATCH
