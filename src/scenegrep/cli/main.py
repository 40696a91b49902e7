"""``scenegrep``: the entry point. Parses the command, runs it, maps errors to exit codes.

Exit codes: 0 success (for queries: some match), 1 no match, 2 user error
(printed as one line ``scenegrep: error: PLACE: MESSAGE``), 3 some source or trace
failed while the others were done, 130 interrupted. Command lines are parsed by the conventions
of :mod:`.parsing` (options before or after positionals; unknown options with suggestions).
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # scenegrep uses no BLAS threads; idle ones spin on a core

import argparse  # noqa: E402
import importlib  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Sequence

from .. import __version__  # noqa: E402
from ..errors import UserError  # noqa: E402
from ..terminal import EscapingStream, OutputError  # noqa: E402
from .exit_codes import EXIT_INTERRUPTED, EXIT_USER_ERROR  # noqa: E402
from .parsing import PROGRAM, CommandParser, parse_command_line  # noqa: E402

COMMANDS = (
    "coverage",
    "evaluate",
    "export",
    "info",
    "ingest",
    "label",
    "report",
    "scenario",
    "scene",
    "serve",
    "show",
    "spre",
    "synth",
)
"""Command modules of this package, each with ``add_parser(subparsers)`` and ``run(args) -> int``."""


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command."""
    parser = CommandParser(
        prog=PROGRAM,
        description="Find the moments in labeled perception data that match a "
        "scenario: Scenic scene and scenario queries, Spatial Regular Expressions.",
    )
    parser.add_argument("--version", action="version", version=f"scenegrep {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=CommandParser)
    for name in COMMANDS:
        importlib.import_module(f"{__package__}.{name}").add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command line; returns the exit code. Text written to standard output and standard
    error goes through :func:`scenegrep.terminal.printable`: names from data never reach a terminal
    as escape sequences."""
    warnings.filterwarnings("ignore", _FLOATING_POINT, RuntimeWarning)
    stdout, stderr = sys.stdout, sys.stderr
    sys.stdout = EscapingStream(stdout)  # type: ignore[assignment]
    sys.stderr = EscapingStream(stderr, keep="\n\t\r")  # type: ignore[assignment]
    try:
        return _run(argv)
    finally:
        sys.stdout, sys.stderr = stdout, stderr


_FLOATING_POINT = "(invalid value|overflow|divide by zero) encountered"
"""numpy's floating-point warnings: NaN or huge numbers in an input, which the data model then
accepts (NaN: unknown) or refuses with a one-line error; never a warning's extra lines."""


def _discard_stdout() -> None:
    """Point standard output at /dev/null so that the interpreter's last flush of what is still
    buffered does not fail again at exit."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.__stdout__.fileno())
    os.close(devnull)


def _run(argv: Sequence[str] | None) -> int:
    try:
        parser = build_parser()
        args = parse_command_line(parser, sys.argv[1:] if argv is None else argv)
        if args.command is None:
            parser.print_help()
            return EXIT_USER_ERROR
        from .options import bag_options_applied

        with bag_options_applied(args):
            code = int(args.run(args))
        sys.stdout.flush()
        return code
    except UserError as exc:
        if isinstance(exc, OutputError):
            _discard_stdout()
        print(f"scenegrep: error: {exc.one_line()}", file=sys.stderr)
        if exc.detail:
            print(exc.detail, file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("scenegrep: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
