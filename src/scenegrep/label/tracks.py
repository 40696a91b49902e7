"""Tracks: the state rows of a trace grouped per object into time-ordered segments, with
window and derivative operations vectorised over every segment at once.

A *segment* is a maximal run of one object's observations, in time order, with no gap longer
than ``max_gap_s`` seconds between consecutive ones. Every operation here works on arrays in
*track order* (:attr:`Tracks.order` permutes state rows into it) and never mixes two segments:
a window is cut at its segment's ends, a derivative uses neighbours of the same segment only.

Every value at a position is computed from the positions its window reads *only*, in an order
fixed by the offsets within the window (no running sum over the segment): the same observations
give bit-identical values whichever earlier observations the trace holds, so a labeller that sees
a bounded history (:mod:`.online`) computes exactly the offline values, ties included. Angles are
never unwrapped into running sums either: :meth:`Tracks.turns` counts, per position, the whole
turns an unwrapping would add (an exact integer sum), and the angle operations read the change
between two positions as the raw difference plus ``2π`` times the difference of their turns.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from ..model import LabelTrace
from ..model.geometry import heading_difference
from ..model.kinematics import track_order

TAU = 2.0 * np.pi


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
        segment; NaN where the window holds no value. The sum is taken in the order of the
        offsets 0, -1, +1, -2, +2, ... (see the module docstring)."""
        known = ~np.isnan(values)
        total = np.where(known, values, 0.0)
        count = known.astype(np.intp)
        for _, shifted, inside in self._offsets(total, known, half):
            np.add(total, shifted, out=total, where=inside)
            count += inside
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(count > 0, total / count, np.nan)

    def _offsets(
        self, values: np.ndarray, known: np.ndarray, half: int
    ) -> Iterator[tuple[int, np.ndarray, np.ndarray]]:
        """For the offsets -1, +1, ..., -half, +half: the offset, ``values`` shifted by it (the
        value at position p + offset, at p) and whether that position is in p's segment and known."""
        n = len(self)
        position = np.arange(n)
        before, after = position - self.start, self.end - 1 - position
        padded = np.concatenate([np.zeros(half), values, np.zeros(half)])
        flags = np.concatenate([np.zeros(half, bool), known, np.zeros(half, bool)])
        for k in range(1, half + 1):
            for offset, room in ((-k, before), (k, after)):
                at = slice(half + offset, half + offset + n)
                yield offset, padded[at], flags[at] & (room >= k)

    def window_any(self, flags: np.ndarray, half: int) -> np.ndarray:
        """Whether any of ``flags`` is set within ``half`` positions either side, inside the segment."""
        count = np.concatenate([[0], np.cumsum(flags)])
        low, high = self._window(half)
        return count[high] > count[low]

    def _window(self, half: int) -> tuple[np.ndarray, np.ndarray]:
        position = np.arange(len(self))
        return np.maximum(position - half, self.start), np.minimum(position + half + 1, self.end)

    def gradient(self, values: np.ndarray, turns: np.ndarray | None = None) -> np.ndarray:
        """Time derivative (units of ``values`` per second): central differences inside a
        segment, one-sided at its ends; NaN for one-observation segments. With ``turns``
        (:meth:`turns`), ``values`` are angles (radians) and the derivative is that of their
        unwrapping."""
        position = np.arange(len(self))
        following = np.minimum(position + 1, self.end - 1)
        previous = np.maximum(position - 1, self.start)
        dt = self.time[following] - self.time[previous]
        with np.errstate(invalid="ignore", divide="ignore"):
            if turns is None:
                change = values[following] - values[previous]
            else:
                change = self.angle_change(values, turns, following, previous)
            return np.where(dt > 0, change / dt, np.nan)

    def turns(self, angles: np.ndarray) -> np.ndarray:
        """Per position, the whole turns (an integer) unwrapping ``angles`` (radians) along its
        segment adds to it: ``angles + 2π·turns`` changes between consecutive known angles by the
        smallest rotation between them. Only differences of turns within a segment mean anything
        (a segment's count starts wherever the trace does); NaN angles add none."""
        position = np.arange(len(self))
        known = ~np.isnan(angles)
        last = np.maximum.accumulate(np.where(known, position, -1))
        previous = np.concatenate([[-1], last[:-1]]) if len(self) else last
        linked = known & (previous >= self.start)
        before = angles[np.maximum(previous, 0)]
        jump = np.zeros(len(self), dtype=np.int64)
        raw = angles[linked] - before[linked]
        jump[linked] = np.rint((heading_difference(angles[linked], before[linked]) - raw) / TAU).astype(np.int64)
        return np.cumsum(jump)

    @staticmethod
    def angle_change(angles: np.ndarray, turns: np.ndarray, to: np.ndarray, since: np.ndarray) -> np.ndarray:
        """The unwrapped change of ``angles`` from positions ``since`` to positions ``to`` (radians)."""
        return angles[to] - angles[since] + TAU * (turns[to] - turns[since])

    def angle_mean(self, angles: np.ndarray, turns: np.ndarray, half: int) -> np.ndarray:
        """The mean of the unwrapped ``angles`` within ``half`` positions either side, inside the
        segment, less the position's whole turns: its angle plus the mean unwrapped change from it
        to the known angles of the window (summed in :meth:`window_mean`'s order); NaN where the
        angle is."""
        known = ~np.isnan(angles)
        total = np.zeros(len(self))
        count = known.astype(np.intp)
        padded_turns = np.concatenate([np.zeros(half, np.int64), turns, np.zeros(half, np.int64)])
        for offset, shifted, inside in self._offsets(angles, known, half):
            other = padded_turns[half + offset : half + offset + len(self)]
            np.add(total, shifted - angles + TAU * (other - turns), out=total, where=inside)
            count += inside
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(known, angles + total / np.maximum(count, 1), np.nan)

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
