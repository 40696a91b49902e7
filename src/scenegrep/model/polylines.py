"""Sets of polylines (lane centrelines, curbs) with vectorised direction queries.

The direction of a polyline at a point follows Scenic (``PolylineRegion.nearestSegmentTo``):
project the point onto the polyline, take the segment holding that arc length, and
return the segment's heading. Zero-length segments are dropped first. The projection is
shapely's ``line_locate_point`` (GEOS ``LengthIndexOfPoint``) computed in C with GEOS's
arithmetic, operation for operation, so bit for bit the same arc length (tested against shapely).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ._project import locate
from .geometry import heading_of_vector
from .lane_shapes import line_strings


class Polylines:
    """Polylines (k_i x 2 arrays, metres) flattened into segments; see the module docstring."""

    def __init__(self, lines: list[np.ndarray] | tuple[np.ndarray, ...]):
        cleaned = [_without_repeats(np.asarray(line, dtype=np.float64)[:, :2]) for line in lines]
        self.lines = cleaned
        counts = np.array([max(len(line) - 1, 0) for line in cleaned], dtype=np.int64)
        self.first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64) if len(counts) else counts
        self.count = counts
        self.last = self.first + np.maximum(counts - 1, 0)
        starts = [line[:-1] for line in cleaned if len(line) > 1]
        ends = [line[1:] for line in cleaned if len(line) > 1]
        self.start = np.concatenate(starts) if starts else np.zeros((0, 2))
        self.end = np.concatenate(ends) if ends else np.zeros((0, 2))
        delta = self.end - self.start
        self.heading = heading_of_vector(delta[:, 0], delta[:, 1])
        owner = np.repeat(np.arange(len(cleaned)), counts)
        lengths = np.hypot(delta[:, 0], delta[:, 1])
        line_lengths = np.bincount(owner, weights=lengths, minlength=len(cleaned)) if len(owner) else np.zeros(0)
        self.base = np.concatenate([[0.0], np.cumsum(line_lengths)[:-1]]) if len(cleaned) else np.zeros(0)
        self.arc_end = np.cumsum(lengths)
        self.local_end = np.concatenate(
            [np.cumsum(lengths[f : f + c]) for f, c in zip(self.first.tolist(), counts.tolist())] or [np.zeros(0)]
        )

    @cached_property
    def geometries(self) -> np.ndarray:
        """One shapely LineString per polyline."""
        return line_strings(self.lines)

    def __len__(self) -> int:
        return len(self.lines)

    def arc_at(self, line: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Arc length (metres from its start) of the point of polyline ``line[i]`` nearest to point
        (x[i], y[i]): ``shapely.line_locate_point``, bit for bit (GEOS's arithmetic in C,
        model/_project.c: the first segment at the least distance, the projection clamped to it);
        -1 where no distance is below the largest double (NaN or huge points, where shapely
        raises) or the polyline has no segment."""
        line = np.ascontiguousarray(line, dtype=np.int64)
        arc = np.empty(len(line))
        locate(
            self.start,
            self.end,
            self.first,
            self.count,
            line,
            np.ascontiguousarray(x, dtype=np.float64),
            np.ascontiguousarray(y, dtype=np.float64),
            arc,
        )
        return arc

    def segment_at(self, line: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Index (into the flat segment arrays) of the segment of polyline ``line[i]`` nearest
        to point i, by projection (Scenic's rule: the segment holding :meth:`arc_at`). ValueError
        for a polyline of a single point (no segment) and for a point with no finite distance to
        its polyline (NaN, infinite or beyond about 1e154 m): no segment is guessed for it."""
        line = np.asarray(line, dtype=np.intp)
        if not self.count[line].all():
            raise ValueError("a polyline of a single point has no direction")
        arc = self.arc_at(line, x, y)
        if (arc < 0).any():
            raise ValueError("a point with no finite distance to its polyline has no nearest segment")
        low, high = self.first.take(line), self.last.take(line)
        found = np.minimum(np.maximum(np.searchsorted(self.arc_end, arc + self.base.take(line)), low), high)
        # the global search can be off by one at ties; settle them on the per-line arc lengths,
        # summed as Scenic sums them: the first segment whose end is at or beyond the arc
        previous = np.maximum(found - 1, low)
        found = np.where((found > low) & (arc <= self.local_end.take(previous)), previous, found)
        following = np.minimum(found + 1, high)
        return np.where((found < high) & (arc > self.local_end.take(found)), following, found)

    def direction_at(self, line: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Heading (radians) of polyline ``line[i]`` at point i (its nearest segment's heading)."""
        if len(np.atleast_1d(line)) == 0:
            return np.zeros(0)
        return self.heading[self.segment_at(line, x, y)]


def _without_repeats(points: np.ndarray) -> np.ndarray:
    """The polyline without consecutive duplicate vertices."""
    if len(points) < 2:
        return points
    keep = np.ones(len(points), dtype=bool)
    keep[1:] = np.any(np.diff(points, axis=0) != 0, axis=1)
    return points[keep]
