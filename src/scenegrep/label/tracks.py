"""Tracks: the state rows of a trace grouped per object into time-ordered segments, with
window and derivative operations vectorised over every segment at once.

A *segment* is a maximal run of one object's observations, in time order, with no gap longer
than ``max_gap_s`` seconds between consecutive ones. Every operation here works on arrays in
*track order* (:attr:`Tracks.order` permutes state rows into it) and never mixes two segments:
a window is cut at its segment's ends, a derivative uses neighbours of the same segment only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import LabelTrace
from ..model.geometry import heading_difference
from ..model.kinematics import track_order


@dataclass(frozen=True)
class Tracks:
    """Segments of a trace's state rows; see the module docstring.

    ``order`` maps track-order positions to state rows; ``start`` and ``end`` give, per
    position, its segment's first position and one past its last; ``time`` is in seconds;
    ``interval`` is the median time between consecutive observations of a segment (s).
    """

    order: np.ndarray
    start: np.ndarray
    end: np.ndarray
    time: np.ndarray
    interval: float

    @classmethod
    def of(cls, trace: LabelTrace, max_gap_s: float, interval: float | None = None) -> Tracks:
        """The segments of ``trace``'s states; ``interval`` (s) replaces the median of the trace's
        own steps (the online labeller pins it, :mod:`.online`)."""
        order = track_order(trace.states)
        obj = trace.states.object[order]
        time = trace.frame_time[trace.states.frame[order]]
        step = np.diff(time)
        breaks = np.ones(len(order), dtype=bool)
        breaks[1:] = (obj[1:] != obj[:-1]) | (step > max_gap_s)
        first = np.flatnonzero(breaks)
        sizes = np.diff(np.append(first, len(order)))
        start = np.repeat(first, sizes)
        inside = step[~breaks[1:]]
        if interval is None:
            interval = float(np.median(inside)) if len(inside) else 0.1
        return cls(order, start, start + np.repeat(sizes, sizes), time, interval)

    def __len__(self) -> int:
        return len(self.order)

    def frames(self, seconds: float) -> int:
        """How many observation intervals make ``seconds`` (at least 1)."""
        return max(1, round(seconds / self.interval)) if self.interval > 0 else 1

    def is_first(self) -> np.ndarray:
        """Whether each position starts its segment."""
        return self.start == np.arange(len(self))

    def window_mean(self, values: np.ndarray, half: int) -> np.ndarray:
        """Mean of the non-NaN ``values`` within ``half`` positions either side, inside the
        segment; NaN where the window holds no value."""
        known = ~np.isnan(values)
        total = np.concatenate([[0.0], np.cumsum(np.where(known, values, 0.0))])
        count = np.concatenate([[0], np.cumsum(known)])
        low, high = self._window(half)
        n = count[high] - count[low]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(n > 0, (total[high] - total[low]) / n, np.nan)

    def window_any(self, flags: np.ndarray, half: int) -> np.ndarray:
        """Whether any of ``flags`` is set within ``half`` positions either side, inside the segment."""
        count = np.concatenate([[0], np.cumsum(flags)])
        low, high = self._window(half)
        return count[high] > count[low]

    def _window(self, half: int) -> tuple[np.ndarray, np.ndarray]:
        position = np.arange(len(self))
        return np.maximum(position - half, self.start), np.minimum(position + half + 1, self.end)

    def gradient(self, values: np.ndarray) -> np.ndarray:
        """Time derivative (units of ``values`` per second): central differences inside a
        segment, one-sided at its ends; NaN for one-observation segments."""
        position = np.arange(len(self))
        following = np.minimum(position + 1, self.end - 1)
        previous = np.maximum(position - 1, self.start)
        dt = self.time[following] - self.time[previous]
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(dt > 0, (values[following] - values[previous]) / dt, np.nan)

    def unwrap(self, angles: np.ndarray) -> np.ndarray:
        """Angles (radians) made continuous along each segment: each step is the smallest
        rotation between consecutive angles; a segment starts at its first angle."""
        step = np.zeros(len(self))
        step[1:] = heading_difference(angles[1:], angles[:-1])
        step[self.is_first() | np.isnan(step)] = 0.0
        total = np.cumsum(step)
        return angles[self.start] + total - total[self.start]

    def forward_fill(self, codes: np.ndarray, missing: int = -1) -> np.ndarray:
        """Integer ``codes`` with each ``missing`` one replaced by the last known code of its segment
        (``missing`` where the segment has none yet)."""
        position = np.arange(len(self))
        known = (codes != missing) | self.is_first()
        last = np.maximum.accumulate(np.where(known, position, 0))
        return codes[last]

    def change_from(self, codes: np.ndarray) -> np.ndarray:
        """The code at the previous position of the same segment (``-1`` at a segment's start)."""
        previous = np.full(len(self), -1, dtype=codes.dtype)
        previous[1:] = codes[:-1]
        previous[self.is_first()] = -1
        return previous

    def runs(self, flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Maximal runs of set ``flags`` inside segments: per position, the first and the last
        position of its run (meaningful where the flag is set)."""
        position = np.arange(len(self))
        if not flags.any():
            return position, position
        begins = flags & (self.is_first() | ~np.roll(flags, 1))
        ends = flags & ((position == self.end - 1) | ~np.roll(flags, -1))
        first = np.maximum.accumulate(np.where(begins, position, 0))
        run_ends = np.flatnonzero(ends)
        last = run_ends[np.minimum(np.searchsorted(run_ends, position), len(run_ends) - 1)]
        return first, last

    def to_rows(self, values: np.ndarray) -> np.ndarray:
        """Values in track order put back in the trace's state-row order."""
        out = np.empty_like(values)
        out[self.order] = values
        return out
