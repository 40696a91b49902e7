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
strem``; the first bad input ends the command (exit code 2). The stream searches, the match lines
and the warnings for names the data lacks (per input; for a live stream once it has ended) are
:mod:`scenegrep.streams.spre`'s. Exit codes: 0 some match, 1 none, 2 error, 3 some file failed.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable
from typing import Any

from .dataset_run import print_warnings, run_query_command
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


def _report(
    matches: Iterable[Any], source: str, prefix: str, args: argparse.Namespace, form: Any, trace: Any = None
) -> bool:
    """Print the matches of one input, ``source`` (its path as given, ``-`` for standard input),
    of its ``trace`` (None for a live stream), as ``form`` writes them
    (:class:`~scenegrep.streams.spre.MatchFormat`), at most --max-count (online, the rest are still
    read), with ``--compat strem`` each line starting with STREM's ``prefix``; True when there was any."""
    found = False
    printed = 0
    out = sys.stdout
    for match in matches:
        found = True
        if args.quiet or (args.max_count is not None and printed >= args.max_count):
            if not args.online:
                break
            continue
        out.write(form.text(match, source, prefix, trace) + "\n")
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
    from ..spre import SearchOptions, compile_query
    from ..streams.spre import MatchFormat, input_searches

    query = compile_query(args.pattern, compat=args.compat == "strem")
    for warning in query.warnings:
        print(f"scenegrep: warning: {warning}", file=sys.stderr)
    options = SearchOptions(args.space, tuple(args.channel) if args.channel else None, max(args.skip, 0))
    form = MatchFormat(args.json, args.export, args.compat == "strem", options)
    if args.follow:
        return _run_live(query, args, options, form)
    found = False
    for path in args.files or ["-"]:
        if path == "-" and args.online:
            found |= _run_live(query, args, options, form) == 0
            continue
        for search in input_searches(query, path, options, args.online):
            print_warnings(search.warnings, args)
            found |= _report(search.matches, path, search.prefix, args, form, search.trace)
    return 0 if found else EXIT_NO_MATCH


def _run_live(query: Any, args: argparse.Namespace, options: Any, form: Any) -> int:
    """Online matching of a live input: ``--follow FILE``, or standard input (MCAP or STREM JSON);
    the names the query uses that the stream lacked are said when it has ended."""
    from ..readers.strem_json import iter_documents
    from ..streams.spre import LiveSearch
    from .live import open_input, report, until_stopped

    search = LiveSearch(query, open_input(args, iter_documents), options)
    with until_stopped():
        _report(search.matches, search.live.source, search.prefix, args, form)
    print_warnings(search.warnings, args)
    report(search.live.latency, args)
    return 0 if search.live.latency.found else EXIT_NO_MATCH
