"""The ``ros-bag`` format: MCAP files and ROS 2 bag directories read into one label trace.

:func:`read_traces` runs the incremental pipeline over a bag's messages to the end: each chunk's
messages decoded as it is read, in batches (:func:`.segments.decoded_batches`), framed
(:mod:`.framing`): the bag's frames as one trace. Options (topics, frame topic or rate, map and ego frames) are a
:class:`BagOptions`, by default those in force (:func:`.options.current`).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ...errors import UserError, at
from ...model import LabelTrace, TraceSource
from .bag import bag_runs
from .framing import frames
from .options import BagOptions, current
from .segments import decoded_batches

FORMAT = "ros-bag"


def read_traces(path: str | Path, options: BagOptions | None = None) -> Iterator[LabelTrace]:
    """The bag's trace, or nothing when it holds no box message to build a frame from."""
    source = TraceSource(str(path), FORMAT)
    options = options or current()
    trace = frames(decoded_batches(bag_runs(path, views=True), options), options, Path(path).stem, source)
    if trace is not None:
        yield trace


def read_trace(path: str | Path, options: BagOptions | None = None) -> LabelTrace:
    """The whole bag as one trace (UserError when no frame could be built)."""
    for trace in read_traces(path, options):
        return trace
    raise UserError("no frames: the bag holds no messages of a supported box type (see scenegrep info)", at(path))
