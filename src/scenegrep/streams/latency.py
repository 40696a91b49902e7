"""Latency of a live input's frames and matches, measured around the iterators that carry them.

For every frame, the time from the read of its last message
(:attr:`~scenegrep.readers.mcap_follow.MessageStream.arrival`; for JSON documents the read of the
document) to the end of its processing, that is when the next
chunk is asked for, after its matches were handed out (printed and flushed by the caller); and the
same for each match alone, up to when the next match is asked for. Kept only when asked for (8 bytes
per frame and per match); :meth:`Latency.line` gives their count, median and 99th percentile in
milliseconds.
"""

from __future__ import annotations

import time
from array import array
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from ..wording import counted

T = TypeVar("T")


class Latency:
    """Latencies of frames and matches (seconds), measured around the iterators it wraps when ``keep``
    (8 bytes per frame and per match); ``arrival`` gives the arrival time (s, ``time.perf_counter``'s
    clock) of the chunk just read; ``found``: whether any match was handed out."""

    def __init__(self, arrival: Callable[[], float], keep: bool):
        self.arrival = arrival
        self.keep = keep
        self.current = time.perf_counter()
        self.frames = array("d")
        self.matches = array("d")
        self.found = False

    def chunks(self, chunks: Iterable[Any]) -> Iterator[Any]:
        """``chunks`` (traces); each chunk's frames are timed when the next chunk is asked for."""
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
        return f"latency: {_stats(self.frames, 'frame')}; {_stats(self.matches, 'match')}"


def _stats(times: array, noun: str) -> str:
    """``N nouns, median X ms, p99 Y ms`` of ``times`` (s), or ``N nouns`` when there are none."""
    import numpy as np

    count = counted(len(times), noun)
    if not times:
        return count
    median, p99 = np.percentile(np.array(times) * 1000, [50, 99])
    return f"{count}, median {median:.2f} ms, p99 {p99:.2f} ms"
