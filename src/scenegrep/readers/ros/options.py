"""How a bag's messages become frames: :class:`BagOptions`, and the options in force.

The command line sets the options of one command (``--topics``, ``--frame-topic``, ``--rate``,
``--map-frame``, ``--ego-frame``, ``--ego-size``) with :func:`using`; the reader reads them with
:func:`current` unless it is given options, so every command that reads inputs (``info``,
``scene``, ``scenario``, ``spre``, ...) reads bags the same way without passing them through.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass

from ...errors import UserError

MAX_RATE_HZ = 10_000.0
"""The highest frame rate (--rate) accepted."""

MAX_EGO_SIZE_M = 100.0
"""The largest length, width or height (metres) --ego-size accepts."""


@dataclass(frozen=True)
class BagOptions:
    """``topics`` to read (empty: every supported topic; ``/tf`` and ``/tf_static`` are always
    read), frames on ``frame_topic`` or at ``rate`` Hz (not both; neither: on the first box
    topic met), the ``map_frame`` boxes are placed in, the ego's ``ego_frame`` and its size
    ``ego_size`` (length, width, height in metres; None: unknown, as ``/tf`` and odometry carry
    none, see :data:`~scenegrep.model.trace.EGO_SIZE_UNKNOWN`)."""

    topics: tuple[str, ...] = ()
    frame_topic: str | None = None
    rate: float | None = None
    map_frame: str = "map"
    ego_frame: str = "base_link"
    ego_size: tuple[float, float, float] | None = None

    def __post_init__(self) -> None:
        if self.rate is not None and self.frame_topic is not None:
            raise UserError("give --rate or --frame-topic, not both")
        if self.rate is not None and not (math.isfinite(self.rate) and 1e-3 <= self.rate <= MAX_RATE_HZ):
            raise UserError(f"--rate {self.rate}: a frame rate from 0.001 to {MAX_RATE_HZ:g} Hz")
        if self.ego_size is not None:
            check_ego_size(self.ego_size)
        for name in (self.map_frame, self.ego_frame, self.frame_topic or "x", *self.topics):
            if not name or len(name) > 1000:
                raise UserError(f"a topic or frame name must have 1 to 1000 characters: {name[:40]!r}")


def check_ego_size(size: tuple[float, ...]) -> None:
    """UserError unless ``size`` is three finite lengths over 0 and at most :data:`MAX_EGO_SIZE_M`."""
    if len(size) != 3 or not all(math.isfinite(v) and 0 < v <= MAX_EGO_SIZE_M for v in size):
        shown = ",".join(f"{v:g}" for v in size[:4])
        raise UserError(
            f"--ego-size {shown}: give LENGTH,WIDTH,HEIGHT, three lengths over 0 and at most {MAX_EGO_SIZE_M:g} m"
        )


_CURRENT: ContextVar[BagOptions | None] = ContextVar("bag_options", default=None)


def current() -> BagOptions:
    """The options in force (the defaults unless a command set others)."""
    return _CURRENT.get() or BagOptions()


@contextlib.contextmanager
def using(options: BagOptions) -> Iterator[None]:
    """Read bags with ``options`` within the block."""
    token = _CURRENT.set(options)
    try:
        yield
    finally:
        _CURRENT.reset(token)
