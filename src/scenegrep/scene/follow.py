"""``follow F from X for D`` (and the ``following`` specifier): Scenic's forward Euler walk along a field.

Scenic (``VectorField.followFrom``) takes ``n = max(4, ceil(D / 5))`` equal steps
of ``D / n`` metres, each along the heading Scenic computes for the field at the
current point (:meth:`~.geometry.MapGeometry.scenic_headings`: inside an
intersection, its first connecting lane holding the point). The interval version
encloses the walk for intervals of start and distance: each step takes the one
heading a small box's corners agree on, or else every heading the field may
have in the box.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import UserError
from .geometry import SMALL_BOX_M

MIN_STEPS = 4
"""Scenic's minimum number of steps (``VectorField.minSteps``)."""

STEP_M = 5.0
"""Scenic's default step size (``VectorField.defaultStepSize``), metres."""

MAX_STEPS = 400
"""The most steps a walk may take (2 km): a longer distance is a user error, not a hang."""


def steps_for(distance) -> np.ndarray:
    """Scenic's number of Euler steps for each distance (metres; NaN takes none, a negative
    distance walks back in the minimum); UserError for a distance whose walk would take more than
    :data:`MAX_STEPS` steps."""
    scaled = np.nan_to_num(np.asarray(distance, dtype=float) / STEP_M, nan=0.0)
    if np.any(scaled > MAX_STEPS):
        raise UserError(
            f"'follow' or 'following' for a distance that may exceed {STEP_M * MAX_STEPS:g} m"
            f" ({MAX_STEPS} of Scenic's {STEP_M:g} m steps) is not supported: bound the distance"
        )
    return np.maximum(MIN_STEPS, np.ceil(scaled)).astype(np.intp)


def walk_end(geometry, field, x, y, distance, value) -> tuple[np.ndarray, np.ndarray]:
    """The end (x, y, metres) of Scenic's walk along the field from each (x[i], y[i]) for
    ``distance[i]`` metres."""
    x, y, distance = (np.array(a, dtype=float) for a in (x, y, distance))
    steps = steps_for(distance)
    step = distance / steps
    for k in range(int(steps.max(initial=0))):
        active = np.flatnonzero(k < steps)
        heading = geometry.scenic_headings(field, x[active], y[active], value)
        x[active] += -np.sin(heading) * step[active]
        y[active] += np.cos(heading) * step[active]
    return x, y


def follow_box(geometry, field, x, y, distance, value, covering_arc, intervals):
    """An enclosure of the walk's end (two intervals) for intervals of start and distance, or None
    when the field has no heading somewhere along it. Every step takes every heading the field may
    have in the current box, so the enclosure holds the walk whichever heading Scenic picks."""
    iv = intervals
    results = []
    first, last = (int(n) for n in steps_for(np.array([distance.lo, distance.hi])))
    for steps in range(first, last + 1):
        step = distance / steps
        px, py = x, y
        for _ in range(steps):
            arc = covering_arc(_step_headings(geometry, field, px, py, value))
            if arc is None:
                return None
            px, py = px + (-iv.sin(arc)) * step, py + iv.cos(arc) * step
        results.append((px, py))
    return (
        iv.Interval(min(r[0].lo for r in results), max(r[0].hi for r in results)),
        iv.Interval(min(r[1].lo for r in results), max(r[1].hi for r in results)),
    )


def _step_headings(geometry, field, px, py, value) -> np.ndarray | None:
    """The headings Scenic may take in the box: for a small box those its corners and centre take
    (the field's cells are convex at that scale), else every heading the field may have there."""
    if math.hypot(px.width, py.width) / 2 <= SMALL_BOX_M:
        xs = np.array([px.lo, px.hi, px.lo, px.hi, (px.lo + px.hi) / 2])
        ys = np.array([py.lo, py.lo, py.hi, py.hi, (py.lo + py.hi) / 2])
        return np.unique(geometry.scenic_headings(field, xs, ys, lambda t: np.repeat(value(t)[:1], 5)))
    headings = geometry.field_headings_in_box(field, px.lo, px.hi, py.lo, py.hi, value)
    return None if headings is None else np.append(headings, 0.0)
