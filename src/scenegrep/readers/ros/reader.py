"""The ``ros-bag`` format: MCAP files and ROS 2 bag directories read into one label trace.

:func:`read_traces` runs the incremental pipeline (:mod:`.framing`) over a bag's messages in
batches to the end: the bag's frames as one trace. Options (topics, frame topic or rate, map and ego frames) are a
:class:`BagOptions`, by default those in force (:func:`.options.current`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from itertools import islice
from pathlib import Path

from ...errors import UserError, at
from ...model import LabelTrace, TraceSource
from .bag import bag_messages
from .framing import frames
from .messages import RawMessage
from .options import BagOptions, current

FORMAT = "ros-bag"

BATCH = 1024
"""Messages decoded together by the offline reader."""


def batches(messages: Iterable[RawMessage], size: int = BATCH) -> Iterator[list[RawMessage]]:
    """``messages`` in lists of ``size`` (the last may be shorter)."""
    iterator = iter(messages)
    while batch := list(islice(iterator, size)):
        yield batch


def read_traces(path: str | Path, options: BagOptions | None = None) -> Iterator[LabelTrace]:
    """The bag's trace, or nothing when it holds no box message to build a frame from."""
    source = TraceSource(str(path), FORMAT)
    trace = frames(batches(bag_messages(path, views=True)), options or current(), Path(path).stem, source)
    if trace is not None:
        yield trace


def read_trace(path: str | Path, options: BagOptions | None = None) -> LabelTrace:
    """The whole bag as one trace (UserError when no frame could be built)."""
    for trace in read_traces(path, options):
        return trace
    raise UserError("no frames: the bag holds no messages of a supported box type (see scenegrep info)", at(path))
