"""Exact decision, with a witness, of a row whose object follows ``roadDirection`` from a random
start for a random distance, by inverting the walk (``following roadDirection from spot for D``
with ``spot`` on a curb, in a region such as ``road`` or ``intersection``, or a vector of ranges
``Range(a, b) @ Range(c, d)``).

A row qualifies when its only unknowns are the start and the distance D (a finite range), every
``follow`` term walks from that start for D over the lanes field, and every bound is on the walk's
end (its x, its y, its heading: the road direction there), the end boxed in x and y. The start
is a point on a curb, a point in a region made of map layers, or two range variables (a box).

:func:`~..follow_inverse.preimages` gives every (X, D) whose walk ends at the box's centre E: a
few segments ``X = E + D a`` (D in an interval), found backwards from E and pruned to those that
can still reach X's domain. Each segment is met with the domain (a curb segment: one point or,
along it, the middle of the overlap; a region or box: the middle of the part inside), and the
start found there, walked again with Scenic's rule (:func:`~..follow.walk_end`) and checked
against the row's whole system (:func:`.pointwise.satisfies`, requirements included), is the
witness. All rows of a call are inverted together (:func:`start_preimages`).

Refutation: no value the field may take in the end's box (a superset:
:meth:`~..geometry.MapGeometry.field_headings_in_box`) meets the heading bounds, or no preimage
segment meets the domain (no start in the domain walks to E: the preimage holds every walk, see
:mod:`..follow_inverse`) and the end box is at most :data:`REFUTE_BOX_M` across (the preimage
is the centre's: a walk may end in a wider box elsewhere). A row with a wider box and no preimage
start, or whose candidate starts all fail the check (a walk through a cut point, or a requirement
the start does not meet), is undecided, and the caller decides it by the forward enumeration of
:mod:`.walk_start` (a curb start) or by the general solvers.

Speed (Town01, ``benchmarks/bench_follow.py``, CPU ms per one-frame match, median / p95; refuted =
the frames moved 3 m or turned 0.3 rad): see the README (section on ``following``), which keeps
the numbers before and after each change.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np
import shapely

from ..clip import clipped
from ..follow import MAX_STEPS, STEP_M, walk_end
from ..follow_inverse import Preimage, preimages
from ..geometry import MapGeometry
from ..regions import MapRegion, Region
from ..terms import Term
from .branch_prune import Outcome
from .pointwise import bound_violation, satisfies
from .problem import Bound, PointUnknown, Problem
from .walk import ROAD_DIRECTION, _follow_terms, is_end_heading, no_parameters, only_end_box

REFUTE_BOX_M = 1e-3
"""The preimage, of the end box's centre only, refutes a row when the box's half-diagonal is at
most this (metres; the default tolerance gives 1.4e-6): a walk may end in a wider box without
passing through its centre, so a row with a wider box (a real-data tolerance) and no preimage
start is undecided and goes to the caller's fallback."""

FIRST_WALKS = 4
"""How many candidate starts are walked first; the others only when none of those is a witness
(each walk is its own, so the witness, the first candidate that passes, is the same; the first
candidate nearly always passes, and a slow frame has a hundred)."""

PARALLEL = 1e-9
"""A preimage segment and a curb segment whose directions' sine is below this run along each other."""

CURB = MapRegion("curb")


@dataclass(frozen=True)
class StartWalk:
    """The one walk of a row: its start (``x``, ``y`` terms; ``point`` when a random point, with its
    region, else a box of ranges), distance unknown and range (metres), the end's coordinate terms,
    and the box its bounds give the end (x_lo, x_hi, y_lo, y_hi)."""

    x: Term
    y: Term
    point: PointUnknown | None
    distance: Term
    ends: tuple[Term, Term]
    lo: float
    hi: float
    box: tuple[float, float, float, float]

    @property
    def on_curb(self) -> bool:
        return self.point is not None and self.point.region == CURB


def find_start_walk(problem: Problem) -> StartWalk | None:
    """The row's walk when it qualifies (see the module docstring), else None."""
    found = sorted(_follow_terms(problem), key=lambda t: t.value[1])
    if len(found) != 2 or found[0].args != found[1].args or any(t.value[0] != ROAD_DIRECTION for t in found):
        return None
    x, y, distance = found[0].args
    if distance not in problem.scalars or not _start_known(problem, x, y, distance):
        return None
    lo, hi = problem.ranges[distance]
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi and max(-lo, hi) <= STEP_M * MAX_STEPS):
        return None
    ends = (found[0], found[1])
    box = only_end_box(problem, ends)
    if box is None:
        return None
    point = problem.points[0] if problem.points else None
    return StartWalk(x, y, point, distance, ends, lo, hi, box)


def _start_known(problem: Problem, x: Term, y: Term, distance: Term) -> bool:
    """Whether the start is the row's one random point (and D its one variable), or two finite
    range variables other than D (and no point)."""
    if problem.points:
        point = problem.points[0]
        return len(problem.points) == 1 and (point.x, point.y) == (x, y) and problem.scalars == [distance]
    if x is y or {x, y, distance} != set(problem.scalars) or len(problem.scalars) != 3:
        return False
    return all(math.isfinite(v) for u in (x, y) for v in problem.ranges[u])


def domain_of(problem: Problem, walk: StartWalk, geometry: MapGeometry) -> shapely.Geometry | None:
    """Where the start lies (a shapely geometry: the curbs, a region, a box), or None when the
    region is not made of map layers."""
    if walk.point is None:
        (x0, x1), (y0, y1) = problem.ranges[walk.x], problem.ranges[walk.y]
        return shapely.box(x0, y0, x1, y1)
    if not _static(walk.point.region):
        return None
    return geometry.static_geometry(walk.point.region)


def _static(region: Region) -> bool:
    """Whether the region is made of map layers only (no terms: the same for every value)."""
    return not any(True for _ in region.terms())


def start_preimages(
    problems: list[Problem], walks: list[StartWalk | None], geometry: MapGeometry
) -> dict[int, tuple[Preimage, shapely.Geometry]]:
    """The preimages of every qualifying row's end box centre (problem index -> preimage and the
    start's domain), inverted together: curb starts, then the others (whose first heading is
    checked along the way)."""
    found: dict[int, tuple[Preimage, shapely.Geometry]] = {}
    for curb in (True, False):
        rows, domains = [], []
        for k, walk in enumerate(walks):
            if walk is None or walk.on_curb != curb:
                continue
            domain = domain_of(problems[k], walk, geometry)
            if domain is not None and not domain.is_empty:
                rows.append(k)
                domains.append(domain)
        if not rows:
            continue
        box = np.array([walks[k].box for k in rows])  # type: ignore[union-attr]
        span = np.array([(walks[k].lo, walks[k].hi) for k in rows])  # type: ignore[union-attr]
        ex, ey = (box[:, 0] + box[:, 1]) / 2, (box[:, 2] + box[:, 3]) / 2
        domain = np.array(domains, dtype=object)
        pre = preimages(geometry, ROAD_DIRECTION, ex, ey, span[:, 0], span[:, 1], not curb, domain)
        order = np.argsort(pre.row, kind="stable")
        cuts = np.searchsorted(pre.row[order], np.arange(len(rows) + 1))
        for i, k in enumerate(rows):
            found[k] = (pre.take(order[cuts[i] : cuts[i + 1]]), domains[i])
    return found


def solve_start_walk(
    problem: Problem, walk: StartWalk, geometry: MapGeometry, pre: Preimage, domain: shapely.Geometry
) -> Outcome:
    """Decide the row from the preimage of its end box's centre (see the module docstring)."""
    x0, x1, y0, y1 = walk.box
    headings = [b for b in problem.bounds if is_end_heading(b.term, walk.ends)]
    if headings and not _heading_possible(geometry, walk.box, headings):
        return Outcome("unsat", None, "follow-start")
    ex, ey = (x0 + x1) / 2, (y0 + y1) / 2
    lines = _segments(ex, ey, pre)
    margin = math.hypot(x1 - x0, y1 - y0) / 2 + 1e-9
    if walk.on_curb:
        d, sx, sy = _on_curbs(geometry, ex, ey, pre, lines, margin)
    else:
        d, sx, sy = _inside(ex, ey, pre, lines, domain)
    if not len(d):
        return Outcome("unsat" if margin <= REFUTE_BOX_M else "undecided", None, "follow-start")
    first = min(FIRST_WALKS, len(d))
    for part in (np.arange(first), np.arange(first, len(d))):
        end_x, end_y = walk_end(geometry, ROAD_DIRECTION, sx[part], sy[part], d[part], no_parameters)
        ends = (end_x >= x0) & (end_x <= x1) & (end_y >= y0) & (end_y <= y1)
        for k in np.flatnonzero(ends).tolist():
            i = int(part[k])
            assignment = {walk.distance: float(d[i]), walk.x: float(sx[i]), walk.y: float(sy[i])}
            walked = {**assignment, walk.ends[0]: float(end_x[k]), walk.ends[1]: float(end_y[k])}
            if satisfies(problem, geometry, walked):
                return Outcome("sat", assignment, "follow-start")
    return Outcome("undecided", None, "follow-start")


def _heading_possible(geometry: MapGeometry, box, headings: list[Bound]) -> bool:
    """Whether some value the field may take in the end's box meets every heading bound."""
    values = geometry.field_headings_in_box(ROAD_DIRECTION, box[0], box[1], box[2], box[3], no_parameters)
    if values is None:
        return True
    return any(all(bound_violation(float(h), b) <= 0 for b in headings) for h in values.tolist())


def _segments(ex: float, ey: float, pre: Preimage) -> np.ndarray:
    """The preimage's start segments ``E + D a`` (D from lo to hi), as line strings (a point where
    the segment has no length)."""
    p = np.stack([ex + pre.lo * pre.ax, ey + pre.lo * pre.ay], axis=1)
    q = np.stack([ex + pre.hi * pre.ax, ey + pre.hi * pre.ay], axis=1)
    lines = shapely.linestrings(np.stack([p, q], axis=1))
    still = np.all(p == q, axis=1)
    lines[still] = shapely.points(p[still])
    return lines


def _on_curbs(geometry: MapGeometry, ex, ey, pre: Preimage, lines, margin: float):
    """(D, x, y) of the candidate starts on a curb: where a preimage segment meets a curb segment
    (within ``margin``), or the middle of the stretch where it runs along one."""
    curbs = geometry._require_map().curb_polylines
    tree = _curb_tree(geometry)
    seg, curb = tree.query(lines, predicate="dwithin", distance=margin)
    a = np.stack([pre.ax[seg], pre.ay[seg]], axis=1)
    start = curbs.start[curb]
    w = curbs.end[curb] - start
    rel = start - np.array([ex, ey])
    denom = _cross(a, w)
    size = np.hypot(*a.T) * np.hypot(*w.T)
    parallel = np.abs(denom) <= PARALLEL * np.maximum(size, 1e-300)
    safe = np.where(parallel, 1.0, denom)
    d_cross = _cross(rel, w) / safe
    aa = np.maximum(np.einsum("ij,ij->i", a, a), 1e-300)
    ends = np.stack([np.einsum("ij,ij->i", rel, a), np.einsum("ij,ij->i", rel + w, a)], axis=1) / aa[:, None]
    low = np.maximum(pre.lo[seg], ends.min(axis=1))
    high = np.minimum(pre.hi[seg], ends.max(axis=1))
    d = np.where(parallel, (low + high) / 2, np.clip(d_cross, pre.lo[seg], pre.hi[seg]))
    point = np.array([ex, ey]) + d[:, None] * a
    s = np.clip(np.einsum("ij,ij->i", point - start, w) / np.einsum("ij,ij->i", w, w), 0.0, 1.0)
    on = start + s[:, None] * w
    keep = ~parallel | (low <= high)
    return d[keep], on[keep, 0], on[keep, 1]


def _inside(ex, ey, pre: Preimage, lines, domain: shapely.Geometry):
    """(D, x, y) of the candidate starts in a region or box: the middle of each preimage segment's
    first part inside it (a line, or a point where it only touches)."""
    inside = clipped(lines, domain)
    hit = np.flatnonzero(~shapely.is_empty(inside))
    if not len(hit):
        return np.zeros(0), np.zeros(0), np.zeros(0)
    first = shapely.get_geometry(inside[hit], 0)  # a collection's first part; any other non-empty geometry itself
    line = shapely.get_type_id(first) == 1
    first[line] = shapely.line_interpolate_point(first[line], 0.5, normalized=True)
    middle = shapely.get_coordinates(first)
    a = np.stack([pre.ax[hit], pre.ay[hit]], axis=1)
    aa = np.maximum(np.einsum("ij,ij->i", a, a), 1e-300)
    d = np.clip(np.einsum("ij,ij->i", middle - np.array([ex, ey]), a) / aa, pre.lo[hit], pre.hi[hit])
    return d, middle[:, 0], middle[:, 1]


def _curb_tree(geometry: MapGeometry) -> shapely.STRtree:
    """An R-tree of the map's curb segments (flat indices of its curb polylines), built once."""
    found = _CURB_TREES.get(geometry)
    if found is None:
        curbs = geometry._require_map().curb_polylines
        found = _CURB_TREES[geometry] = shapely.STRtree(shapely.linestrings(np.stack([curbs.start, curbs.end], axis=1)))
    return found


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


_CURB_TREES: weakref.WeakKeyDictionary[MapGeometry, shapely.STRtree] = weakref.WeakKeyDictionary()
