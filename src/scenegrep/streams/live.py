"""Live inputs of the online queries: an MCAP file followed as it is written, or standard input.

:func:`open_live` opens one: ``follow`` names an MCAP file to follow like ``tail -f``
(:func:`scenegrep.readers.mcap_follow.follow_mcap`); without it standard input is read, as an MCAP
stream when it starts with MCAP's magic bytes, else as the query's own JSON documents (its
``documents`` decoder: STREM JSON documents for SpRE, :func:`trace_documents` for a scenario). MCAP
messages become frames by :func:`scenegrep.readers.live_frames.live_chunks` (JSON document channels,
and the bag pipeline with the bag options in force; its notes go to ``note``). The chunks come with
their :class:`~scenegrep.streams.latency.Latency` meter: each chunk's arrival is the read of its last
MCAP message, or for JSON documents the moment the document was decoded.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from ..model import LabelTrace
from .latency import Latency


@dataclass
class LiveInput:
    """The frames of a live input as chunks (traces, in order), their latency meter, and the
    input's ``source``: the path followed, ``-`` for standard input."""

    chunks: Iterator[LabelTrace]
    latency: Latency
    source: str


def open_live(
    follow: str | None,
    documents: Callable[[BinaryIO], Iterable[LabelTrace]],
    *,
    idle_timeout: float | None = None,
    keep_latency: bool = False,
    note: Callable[[str], None] = lambda text: None,
    stdin: BinaryIO | None = None,
) -> LiveInput:
    """The live input (see the module docstring): the MCAP file ``follow`` (stopping after
    ``idle_timeout`` s without new bytes; None: at the writer's end), else ``stdin`` (default: the
    process's standard input), MCAP or ``documents``. Latencies are kept with ``keep_latency``. Bad
    input is a :class:`~scenegrep.errors.UserError` when it is read, naming its place."""
    if follow is not None:
        chunks, latency = mcap_chunks(follow, idle_timeout, keep_latency, note)
        return LiveInput(chunks, latency, follow)
    from ..readers.mcap_follow import sniff_mcap

    is_mcap, stream = sniff_mcap(stdin if stdin is not None else sys.stdin.buffer)
    if is_mcap:
        chunks, latency = mcap_chunks("-", idle_timeout, keep_latency, note, stream)
    else:
        latency = Latency(time.perf_counter, keep_latency)
        chunks = latency.chunks(documents(stream))
    return LiveInput(chunks, latency, "-")


def mcap_chunks(
    path: str,
    idle_timeout: float | None,
    keep_latency: bool,
    note: Callable[[str], None],
    stdin: BinaryIO | None = None,
) -> tuple[Iterator[LabelTrace], Latency]:
    """The frames of the MCAP stream at ``path`` (``-``: ``stdin``) as chunks, and their latency meter;
    the trace is named after the file's stem (``stdin`` for standard input)."""
    from ..model import TraceSource
    from ..readers.live_frames import live_chunks
    from ..readers.mcap_follow import FollowOptions, follow_mcap

    messages = follow_mcap(path, FollowOptions(idle_timeout=idle_timeout), stdin)
    latency = Latency(lambda: messages.arrival, keep_latency)
    name = "stdin" if path == "-" else Path(path).stem
    chunks = live_chunks(messages.batches(), name, TraceSource(messages.name, "ros-bag"), note)
    return latency.chunks(chunks), latency


def trace_documents(stream: BinaryIO) -> Iterator[LabelTrace]:
    """The scenegrep JSON trace documents of ``stream``, one per line (blank lines skipped), each
    decoded as it is read; a bad one is a UserError at ``<stdin>:LINE``."""
    from ..readers.trace_json import decode

    lines = ((number, line) for number, line in enumerate(stream, start=1) if line.strip())
    return (decode(line, f"<stdin>:{number}", "stdin") for number, line in lines)
