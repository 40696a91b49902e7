"""Live input of the online commands (``scenario --online``, ``spre --online``): the options turned
into the Python API's live input (:mod:`scenegrep.streams.live`: an MCAP stream followed as it is
written, ``--follow FILE``, or standard input, MCAP or the command's JSON documents), its notes and
the latency line (:mod:`scenegrep.streams.latency`) on stderr.

While a live input is read, SIGTERM stops the command as Ctrl-C does, and either ends it cleanly: what
was matched stands (exit code 0 or 1), the warnings and the latency line are printed.
"""

from __future__ import annotations

import argparse
import signal
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any, BinaryIO


def open_input(args: argparse.Namespace, documents: Callable[[BinaryIO], Iterable[Any]]) -> Any:
    """The :class:`~scenegrep.streams.live.LiveInput` of ``--follow FILE`` or standard input, with
    ``--idle-timeout`` and ``--latency``; the bag reader's notes on stderr."""
    from ..streams.live import open_live

    return open_live(args.follow, documents, idle_timeout=args.idle_timeout, keep_latency=args.latency, note=_note)


def _note(text: str) -> None:
    print(f"scenegrep: note: {text}", file=sys.stderr, flush=True)


def report(latency: Any, args: argparse.Namespace) -> None:
    """The latency line on stderr, with ``--latency``."""
    if args.latency:
        print(f"scenegrep: {latency.line()}", file=sys.stderr)


@contextmanager
def until_stopped() -> Iterator[None]:
    """Run the body until it ends, Ctrl-C or SIGTERM; the last two end it as if the input had ended."""

    def stop(signum: int, frame: Any) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
