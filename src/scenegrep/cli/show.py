"""``scenegrep show RESULT_OR_TRACE [--match N] -o OUT``: a picture or page of a match or a trace.

RESULT_OR_TRACE is a results table (Parquet, JSON lines or CSV, written by a ``--dataset`` run;
its traces are read from the dataset it lies in, or ``--dataset``) or a trace file of any
readable format. OUT's suffix chooses: ``.png`` one frame, ``.gif`` the window played, ``.html``
an interactive page. Exit codes: 0 written, 2 user error.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import UserError
from .options import check_output_file


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "show",
        help="draw a match or a trace: top-down map, objects, the program's objects (PNG, GIF, HTML)",
        description="Draw a trace on its road map with the objects as oriented boxes coloured by class; for a "
        "match, the corresponded objects highlighted with the program's names, their paths, their behaviour "
        "labels along the time line and the match window marked. A SpRE's matches over image detections show "
        "the boxes of the classes the query names. The .html page is self-contained (play, scrub, hover).",
    )
    parser.add_argument("target", metavar="RESULT_OR_TRACE", help="a results table (.parquet/.json/.csv) or a trace")
    parser.add_argument("-o", "--output", required=True, metavar="OUT", help="the .png, .gif or .html file to write")
    parser.add_argument(
        "--match", type=int, metavar="N", help="which match: N-th of the table (0-based, default 0), or of --trace"
    )
    parser.add_argument(
        "--trace",
        metavar="TRACE",
        help="show this trace of the results (matched or not): its trace_id, name, source file, SOURCE#NAME, "
        "or a match line's SOURCE#NAME:START-END or NAME:START-END (that match)",
    )
    parser.add_argument("--frame", type=int, metavar="INDEX", help="PNG: the dataset frame index to draw")
    parser.add_argument("--dataset", metavar="DATASET", help="the dataset of the results (default: where they lie)")
    parser.add_argument("--map", metavar="MAP", help="a trace file's road map (default: the trace's own)")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..view.sources import ResultsSource, is_results, trace_file_view
    from ..view.trace_names import chosen_match

    check_output_file("-o", args.output, (".png", ".gif", ".html"))
    if is_results(args.target):
        source = ResultsSource.open(args.target, args.dataset)
        trace_id, number = chosen_match(source, args.trace, args.match)
        view = source.view(trace_id)
        match = view.match(number) if number is not None else None
    else:
        if args.trace is not None or args.dataset is not None:
            raise UserError(f"{args.target}: --trace and --dataset go with a results table, not a trace")
        view = trace_file_view(args.target, args.map)
        match = None
    _write(view, match, args)
    if not args.quiet:
        shown = f"match {match.number} of " if match is not None else ""
        print(f"scenegrep: {shown}{view.trace.name} drawn in {args.output}", file=sys.stderr)
    return 0


def _write(view: Any, match: Any, args: argparse.Namespace) -> None:
    from ..writers.atomic import atomic_path

    kind = Path(args.output).suffix.lower()[1:]
    if kind == "html":
        from ..view.page import view_page

        content = view_page(view, initial_match=None if match is None else match.number).encode()
    else:
        from ..view.plot import picture

        content = picture(view, kind, match, None if args.frame is None else _position(view, args.frame))
    with atomic_path(args.output) as tmp:
        tmp.write_bytes(content)


def _position(view: Any, index: int) -> int:
    from ..view.data import frame_positions

    positions = frame_positions(view.trace)
    if index not in positions:
        raise UserError(f"--frame {index}: the trace has no frame with that index")
    return positions[index]
