"""``scenegrep ingest SOURCE... --into DATASET``: build or update a dataset.

Every source (a file or recording directory of any supported format, or a directory searched
for them) becomes scenegrep Parquet traces in ``DATASET/traces`` and rows of the catalog
``DATASET/catalog.duckdb``; unchanged sources are skipped. Exit codes: 0 every source
ingested or unchanged, 2 user error, 3 some source failed (each named on stderr; the others
are ingested).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from ..errors import UserError
from .exit_codes import EXIT_SOME_FAILED
from ..wording import counted
from .options import add_jobs_argument, add_map_argument, add_unknown_layers_argument, report_unknown_layers


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "ingest",
        help="convert inputs into a dataset: Parquet traces and a DuckDB catalog",
        description="Convert inputs of any supported format (files, recording directories, or directories holding "
        "them) into a dataset directory: one Parquet file per trace, the road maps, and a catalog in DuckDB "
        "(traces, objects per class, per-class counts per frame, behaviour label statistics, sources and "
        "checksums). Incremental: re-running skips unchanged sources. Traces without behaviour labels are "
        "labelled (scenegrep label's labeller) unless --no-label.",
    )
    parser.add_argument("sources", nargs="+", metavar="SOURCE", help="inputs or directories of inputs")
    parser.add_argument(
        "-o",
        "--output",
        "--into",
        dest="into",
        required=True,
        metavar="DATASET",
        help="the dataset directory (created if needed)",
    )
    add_jobs_argument(parser)
    parser.add_argument("--no-label", action="store_true", help="do not label traces without behaviour labels")
    parser.add_argument("-q", "--quiet", action="store_true", help="print only errors")
    add_unknown_layers_argument(parser)
    add_map_argument(parser)
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from ..dataset.ingest import ingest
    from ..progress import bar as progress_bar

    _check_dataset_folder(args.into)
    with progress_bar(quiet=args.quiet, unit="source", leave=False) as bar:
        report = ingest(
            args.sources,
            args.into,
            args.jobs,
            not args.no_label,
            on_outcome=lambda _: bar.update(),
            unknown_layers=args.unknown_layers,
            map_path=args.map,
        )
    for path, error in report.failed:
        print(f"scenegrep: error: {error if error.startswith(path) else f'{path}: {error}'}", file=sys.stderr)
    if not args.quiet:
        print(
            f"scenegrep: {counted(report.ingested, 'source')} ingested ({counted(report.traces, 'trace')}), "
            f"{report.unchanged} unchanged, "
            f"{len(report.failed)} failed; dataset {args.into}",
            file=sys.stderr,
        )
    from ..model.layers import UnknownLayers

    report_unknown_layers(UnknownLayers(args.unknown_layers, report.assumed))
    return EXIT_SOME_FAILED if report.failed else 0


def _check_dataset_folder(into: str) -> None:
    """UserError, before anything is made, for a dataset directory that cannot be one: an empty or
    blank name (not the working directory by accident), a path that is a file or lies under one, or a
    name the file system refuses."""
    if not into.strip():
        raise UserError("-o: give the dataset directory")
    path = Path(into)
    try:
        existing = next((folder for folder in (path, *path.parents) if folder.exists()), None)
    except OSError as error:  # (a name the file system refuses, such as one too long)
        raise UserError(f"-o {into}: {error.strerror}") from None
    if existing is not None and not existing.is_dir():
        below = "" if existing == path else f" ({existing} is a file)"
        raise UserError(f"-o {into}: not a directory{below}; a dataset is a directory")
