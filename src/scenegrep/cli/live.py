"""Live input of the online commands (``scenario --online``, ``spre --online``): an MCAP stream followed
as it is written (``--follow FILE``) or read from standard input, decoded into chunks of frames, and
each frame's latency.

Standard input is an MCAP stream when it starts with MCAP's magic bytes, else the commands' JSON
documents as before. MCAP messages become frames by :func:`scenegrep.readers.live_frames.live_chunks` (JSON document
channels, and the bag pipeline with the bag options in force).
While a live input is read, SIGTERM stops the command as Ctrl-C does, and either ends it cleanly: what
was matched stands (exit code 0 or 1), the latency line is printed.

Latency (``--latency``, one line on stderr at the end): for every frame, the time from the read of its
last message (:attr:`~scenegrep.readers.mcap_follow.MessageStream.arrival`; for JSON documents the read
of the document) to the end of its processing, that is after its matches were printed and flushed;
and the same for each match alone. Median and 99th percentile in milliseconds.
"""

from __future__ import annotations

import argparse
from array import array
import signal
import sys
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, BinaryIO, TypeVar

T = TypeVar("T")


class Latency:
    """Latencies of frames and matches (seconds), measured around the iterators it wraps when ``keep``
    (8 bytes per frame and per match); ``found``: whether any match was handed out."""

    def __init__(self, arrival: Callable[[], float], keep: bool):
        self.arrival = arrival
        self.keep = keep
        self.current = time.perf_counter()
        self.frames = array("d")
        self.matches = array("d")
        self.found = False

    def chunks(self, chunks: Iterable[Any]) -> Iterator[Any]:
        """``chunks``; each chunk's frames are timed when the next chunk is asked for."""
        for chunk in chunks:
            self.current = self.arrival()
            yield chunk
            if self.keep:
                self.frames.extend([time.perf_counter() - self.current] * chunk.n_frames)

    def each_match(self, matches: Iterable[T]) -> Iterator[T]:
        """``matches``; each is timed when the next is asked for (after it was printed)."""
        for match in matches:
            self.found = True
            yield match
            if self.keep:
                self.matches.append(time.perf_counter() - self.current)

    def line(self) -> str:
        """``latency: N frames, median X ms, p99 Y ms; M matches, median ..., p99 ...``."""
        return f"latency: {_stats(self.frames, 'frame', 'frames')}; {_stats(self.matches, 'match', 'matches')}"


def _stats(times: array, one: str, many: str) -> str:
    import numpy as np

    count = f"1 {one}" if len(times) == 1 else f"{len(times)} {many}"
    if not times:
        return count
    median, p99 = np.percentile(np.array(times) * 1000, [50, 99])
    return f"{count}, median {median:.2f} ms, p99 {p99:.2f} ms"


def standard_input() -> tuple[bool, BinaryIO]:
    """Whether standard input is an MCAP stream, and standard input with nothing consumed."""
    from ..readers.mcap_follow import sniff_mcap

    return sniff_mcap(sys.stdin.buffer)


def mcap_chunks(path: str, args: argparse.Namespace, stdin: BinaryIO | None = None) -> tuple[Iterator[Any], Latency]:
    """The frames of the MCAP stream at ``path`` (``-``: ``stdin``) as chunks, and their latency meter."""
    from ..model import TraceSource
    from ..readers.live_frames import live_chunks
    from ..readers.mcap_follow import FollowOptions, follow_mcap

    messages = follow_mcap(path, FollowOptions(idle_timeout=args.idle_timeout), stdin)
    latency = Latency(lambda: messages.arrival, args.latency)
    name = "stdin" if path == "-" else Path(path).stem
    chunks = live_chunks(messages.batches(), name, TraceSource(messages.name, "ros-bag"), _note)
    return latency.chunks(chunks), latency


def _note(text: str) -> None:
    print(f"scenegrep: note: {text}", file=sys.stderr, flush=True)


def report(latency: Latency, args: argparse.Namespace) -> None:
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
