"""``scenegrep serve DATASET``: a local web page to browse a dataset, run queries and open matches.

Binds to 127.0.0.1 only and answers only its own page (see :mod:`scenegrep.view.serve`). Prints
the address, then serves until Ctrl-C (exit 0).
Exit codes: 0 stopped, 2 user error (not a dataset, port in use).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..view.guard import TIME_LIMIT
from .options import add_jobs_argument


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "serve",
        help="a local web page over a dataset: browse traces, run queries, open the matches",
        description="Serve a page on 127.0.0.1 to browse an ingested dataset's traces, type a SpRE or a Scenic "
        "scene or scenario program, run it over the dataset and open every match in its interactive view. "
        "Only the page itself may use the server: requests for another host name, from other web pages "
        "(Origin) or without the page's token are refused; queries never execute Scenic programs' Python, "
        "and options naming files accept files inside the dataset only.",
    )
    parser.add_argument("dataset", metavar="DATASET", help="an ingested dataset directory")
    parser.add_argument("--port", type=int, default=8765, help="the port (default 8765; 0 picks a free one)")
    add_jobs_argument(parser, " per query")
    parser.add_argument(
        "--time-limit",
        type=float,
        default=TIME_LIMIT,
        metavar="SECONDS",
        help=f"stop a query that runs longer (default {TIME_LIMIT:g})",
    )
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dataset import open_dataset
    from ..view.serve import serve

    if not args.time_limit > 0:
        raise UserError(f"--time-limit must be a positive number of seconds (got {args.time_limit})")
    dataset = open_dataset(args.dataset)
    try:
        serve(Path(dataset.path), args.port, args.jobs, args.time_limit)
    except OSError as exc:
        raise UserError(f"cannot serve on 127.0.0.1:{args.port}: {exc.strerror or exc}") from None
    return 0
