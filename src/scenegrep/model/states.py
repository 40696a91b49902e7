"""Per-observation kinematic state of tracked objects: the long table of a label trace.

One row per (frame, object) observation, sorted by frame position then object
row. Units: positions in metres (map frame), heading in radians (Scenic
convention, see :mod:`scenegrep.model.geometry`), sizes in metres, velocity in
m/s (NaN where the dataset gives none). ``lane`` is a code into the trace's lane
id vocabulary, -1 where unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .table import RowTable, float_column, int_column

FLOAT_COLUMNS = ("x", "y", "z", "heading", "length", "width", "height", "vx", "vy")
"""The float64 columns of a :class:`StateTable`, in storage order."""

BLOCK = 1 << 18
"""Rows checked at a time by whole-table checks (their scratch arrays stay small and warm)."""


@dataclass(frozen=True, eq=False)
class StateTable(RowTable):
    """Kinematic observations, one row per (frame, object); see the module docstring for units."""

    frame: np.ndarray
    object: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    heading: np.ndarray
    length: np.ndarray
    width: np.ndarray
    height: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    lane: np.ndarray

    @classmethod
    def build(
        cls, frame, object, x, y, heading, *, z=None, length=None, width=None, height=None, vx=None, vy=None, lane=None
    ) -> StateTable:
        """Make a table from array-likes (missing optional columns become NaN / -1), in the given row order."""
        n = len(frame)
        missing = any(c is None for c in (z, length, width, height, vx, vy))
        nan = np.full(n, np.nan) if missing else None  # (one array for every missing column; none when none is)
        table = cls(
            frame=int_column(frame),
            object=int_column(object),
            x=float_column(x),
            y=float_column(y),
            z=float_column(nan if z is None else z),
            heading=float_column(heading),
            length=float_column(nan if length is None else length),
            width=float_column(nan if width is None else width),
            height=float_column(nan if height is None else height),
            vx=float_column(nan if vx is None else vx),
            vy=float_column(nan if vy is None else vy),
            lane=int_column(np.full(n, -1) if lane is None else lane),
        )
        return table

    def sort_order(self) -> np.ndarray | None:
        """The permutation that orders rows by (frame, object), or None when already ordered."""
        objects = int(self.object.max(initial=0)) + 1
        return (
            None if self.in_order(objects) else np.argsort(order_keys(self.frame, self.object, objects), kind="stable")
        )

    def in_order(self, objects: int) -> bool:
        """Whether the rows are in (frame, object) order without repeats (``objects`` above every
        object code): :func:`order_keys` strictly increasing, checked in blocks of :data:`BLOCK`
        rows (no array of the table's length is made)."""
        n = len(self.frame)
        for start in range(0, n - 1, BLOCK):
            stop = min(start + BLOCK + 1, n)  # (one row of overlap with the next block)
            key = order_keys(self.frame[start:stop], self.object[start:stop], objects)
            if not (key[1:] > key[:-1]).all():
                return False
        return True

    def speed(self) -> np.ndarray:
        """Speed in m/s from the velocity columns (NaN where unknown)."""
        return np.hypot(self.vx, self.vy)

    def frame_offsets(self, n_frames: int) -> np.ndarray:
        """CSR offsets: rows of frame f are ``offsets[f]:offsets[f + 1]`` (length n_frames + 1)."""
        return np.searchsorted(self.frame, np.arange(n_frames + 1), side="left")


def order_keys(frame: np.ndarray, object: np.ndarray, objects: int) -> np.ndarray:
    """``frame * objects + object`` of rows as a new int64 array: increasing along the rows exactly
    when they are in (frame, object) order without repeats, for ``objects`` above every object code."""
    key = frame.astype(np.int64)
    key *= objects
    key += object
    return key
