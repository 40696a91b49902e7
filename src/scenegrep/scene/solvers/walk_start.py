"""Exact decision, with a witness, of a row whose object follows ``roadDirection`` from a random
point on a curb for a random distance (``spot = new OrientedPoint on curb`` then ``following
roadDirection from spot for Range(-30, -20)``).

A row qualifies when its only unknowns are the curb point and the distance D (a finite range),
every ``follow`` term walks from that point for D over the lanes field, and every bound is on
the walk's end (its x, its y, its heading: the road direction there), the end boxed in x and y.
Only curb segments within max |D| of the end's box can start a walk ending there (a walk of n
steps of |D| / n metres); for each, :func:`~..follow_regions.start_regions` gives every (s, D)
whose walk ends in the box, grouped by heading sequence and end heading, exactly. Segments, cut
into pieces of at most 2 m, go first whose walks from a few sampled points and distances end
nearest to the box (within a piece, the branch nearest to that sample first), and the
enumeration stops at the first witness that passes the check below: a match costs the pieces
before it, a refutation all of them. A region whose
end heading meets the heading bounds holds the solutions: its interior point (s, D) is the
witness, walked again with Scenic's rule (:func:`~..follow.walk_end`) and checked against the
row's whole system (:func:`.pointwise.satisfies`, requirements included) before it is reported.

The row is undecided (the caller falls back to the general solvers) when no candidate witness
passes the check (a region through which folded centreline segments compete may take either
segment's heading, so its interior point may walk otherwise: see :mod:`..follow_regions`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from ..follow import MAX_STEPS, STEP_M, walk_end
from ..follow_regions import StartRegion, start_regions
from ..geometry import MapGeometry
from ..regions import MapRegion
from ..terms import Term
from .branch_prune import Outcome
from .pointwise import bound_violation, satisfies
from .problem import PointUnknown, Problem
from .walk import ROAD_DIRECTION, _follow_terms, is_end_heading, no_parameters, only_end_box


GRID = 4
"""Points per side of the grid of further candidate witnesses in a region."""

SAMPLES = 3
"""Points per piece, and distances, of the walks that order the pieces."""

PIECE_M = 2.0
"""Curb segments are enumerated in pieces at most this long (metres), the likeliest first, so that
a match is found without enumerating a long segment whole."""


@dataclass(frozen=True)
class CurbWalk:
    """The one walk of a row: its start point on a curb, distance unknown and range (metres), the
    end's coordinate terms (x, y), and the box its bounds give the end (x_lo, x_hi, y_lo, y_hi)."""

    point: PointUnknown
    distance: Term
    ends: tuple[Term, Term]
    lo: float
    hi: float
    box: tuple[float, float, float, float]


def find_curb_walk(problem: Problem) -> CurbWalk | None:
    """The row's walk when it qualifies (see the module docstring), else None."""
    found = sorted(_follow_terms(problem), key=lambda t: t.value[1])
    if len(found) != 2 or found[0].args != found[1].args or len(problem.points) != 1:
        return None
    x, y, distance = found[0].args
    point = problem.points[0]
    if (point.x, point.y) != (x, y) or point.region != MapRegion("curb") or problem.scalars != [distance]:
        return None
    if any(t.value[0] != ROAD_DIRECTION for t in found):
        return None
    lo, hi = problem.ranges[distance]
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi and max(-lo, hi) <= STEP_M * MAX_STEPS):
        return None
    ends = (found[0], found[1])
    box = only_end_box(problem, ends)
    if box is None:
        return None
    return CurbWalk(point, distance, ends, lo, hi, box)


def solve_curb_walk(problem: Problem, walk: CurbWalk, geometry: MapGeometry) -> Outcome:
    """Decide the row over the regions of its walk (see the module docstring)."""
    road_map = geometry._require_map()
    curbs = road_map.curb_polylines
    x0, x1, y0, y1 = walk.box
    reach = max(-walk.lo, walk.hi)
    near = np.flatnonzero(
        shapely.dwithin(
            shapely.linestrings(np.stack([curbs.start, curbs.end], axis=1)), shapely.box(x0, y0, x1, y1), reach + 1e-9
        )
    )
    if not len(near):
        return Outcome("unsat", None, "follow-regions")  # a walk ends at most |D| from its start
    start, end = _pieces(curbs.start[near], curbs.end[near])
    miss, hints = _sampled_miss(geometry, start, end, walk)
    order = np.argsort(miss, kind="stable")
    start, end, hints = start[order], end[order], hints[order]
    regions = start_regions(geometry, ROAD_DIRECTION, start, end, walk.lo, walk.hi, walk.box, hints)
    headings = [b for b in problem.bounds if is_end_heading(b.term, walk.ends)]
    candidates = 0
    for region in regions:
        if any(bound_violation(region.heading, b) > 0 for b in headings):
            continue
        candidates += 1
        segment = region.segment
        witness = _checked_witness(problem, walk, geometry, start[segment], end[segment], region)
        if witness is not None:
            return Outcome("sat", witness, "follow-regions")
    return Outcome("undecided" if candidates else "unsat", None, "follow-regions")


def _pieces(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The segments cut into equal pieces at most :data:`PIECE_M` long (rows of x, y; metres)."""
    count = np.maximum(1, np.ceil(np.hypot(*(end - start).T) / PIECE_M)).astype(np.intp)
    owner = np.repeat(np.arange(len(start)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    step = (end - start)[owner] / count[owner, None]
    return start[owner] + k[:, None] * step, start[owner] + (k[:, None] + 1) * step


def _sampled_miss(
    geometry: MapGeometry, start: np.ndarray, end: np.ndarray, walk: CurbWalk
) -> tuple[np.ndarray, np.ndarray]:
    """For each piece, how near to the end's box Scenic's walk from a few of its points for a few
    distances of the range comes (metres), and the (s, D) of the nearest: a cheap guess at where
    the walks that match start."""
    x0, x1, y0, y1 = walk.box
    where = np.linspace(0.0, 1.0, SAMPLES)
    points = (start[:, None, :] + where[None, :, None] * (end - start)[:, None, :]).reshape(-1, 2)
    distances = np.linspace(walk.lo, walk.hi, SAMPLES)
    x, y = np.repeat(points[:, 0], SAMPLES), np.repeat(points[:, 1], SAMPLES)
    end_x, end_y = walk_end(geometry, ROAD_DIRECTION, x, y, np.tile(distances, len(points)), no_parameters)
    miss = np.hypot(end_x - (x0 + x1) / 2, end_y - (y0 + y1) / 2).reshape(len(start), -1)
    best = np.argmin(miss, axis=1)
    length = np.hypot(*(end - start).T)
    hints = np.stack([where[best // SAMPLES] * length, distances[best % SAMPLES]], axis=1)
    return miss.min(axis=1), hints


def _checked_witness(
    problem: Problem, walk: CurbWalk, geometry: MapGeometry, a: np.ndarray, b: np.ndarray, region: StartRegion
) -> dict[Term, float] | None:
    """The first of the region's interior point, centroid and points of a grid over it (in
    (s, D)) that, walked again with Scenic's rule, meets the row's whole system, as an assignment;
    else None."""
    direction = (b - a) / np.hypot(*(b - a))
    s0, d0, s1, d1 = region.shape.bounds
    grid = np.stack(np.meshgrid(np.linspace(s0, s1, GRID + 2)[1:-1], np.linspace(d0, d1, GRID + 2)[1:-1]), -1)
    inside = shapely.points(grid.reshape(-1, 2))
    inside = inside[shapely.contains(region.shape, inside)]
    for point in [shapely.point_on_surface(region.shape), shapely.centroid(region.shape), *inside]:
        s, d = shapely.get_x(point), shapely.get_y(point)
        x, y = a + s * direction
        end_x, end_y = walk_end(geometry, ROAD_DIRECTION, [x], [y], [d], None)
        assignment = {walk.distance: float(d), walk.point.x: float(x), walk.point.y: float(y)}
        walked = {**assignment, walk.ends[0]: float(end_x[0]), walk.ends[1]: float(end_y[0])}
        if satisfies(problem, geometry, walked):
            return assignment
    return None
