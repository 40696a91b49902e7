"""The walk ``follow roadDirection from X for D`` inverted: every start X and distance D whose walk
ends at a given point E (the preimage of E), for D in an interval.

Scenic's walk (:mod:`.follow`) takes ``n = max(4, ceil(D / 5))`` steps of ``D / n`` metres, step k
along the field's heading h_k at the point p_k reached so far: ``p_{k+1} = p_k + (D / n) u(h_k)``,
``u(h) = (-sin h, cos h)`` (radians, 0 = +y). Read backwards from ``p_n = E``, each earlier point is
``p_k = p_{k+1} - (D / n) u(h_k)`` for a heading h_k that the field must take *at p_k itself*; the
field takes finitely many values near p_{k+1} (the headings of the centreline segments of lanes and
shoulders within reach, and 0), so each is tried: with the headings h_k .. h_{n-1} chosen, p_k is
``E + D b_k`` with ``b_k = -(1/n) sum_{j>=k} u(h_j)``, affine in D, and it sweeps a segment as D
runs over an interval. Cutting that segment where it crosses the linework of
:mod:`.follow_pieces` gives sub-intervals of D on which the field at p_k is one heading (read at
their midpoints, the assumption :mod:`.follow_pieces` makes); those on which it is h_k are kept.
After n steps backwards the start is ``X = E + D b_0``: the preimage is a set of segments of the
plane (one per heading sequence and D sub-interval), usually a handful.

A candidate heading h_k comes from a segment of a centreline (a lane's, or a shoulder's) within
:attr:`Inverse.reach` of p_k: Scenic reads a point's heading off the nearest segment of the
centreline of the lane or shoulder holding it (or, in an intersection area or within 5 cm of a
lane, of the nearest one), which lies within the lane's reach of the point (the farthest point of
the lane from its centreline) plus the widest gap of an intersection area outside its lanes. A
candidate is also dropped when p_k's segment stays farther than that from every segment with its
heading (no point of that segment can take it). Every rule reads the heading off the segment
of a centreline (a lane's or a shoulder's) holding the point's nearest point of that centreline
(:meth:`~..model.polylines.Polylines.segment_at`), so a segment gives its heading only where that
nearest point may lie on it: not where the point lies :data:`FOOT_SLACK_M` or more before the
segment's start along it and along the segment before it (whose end is then nearer), nor that far
past its end along it and along the next segment. Each candidate segment's D interval is
narrowed to the hull of the D left (Town01's centreline segments are 0.2-0.5 m long and a reach
some metres, so most candidates fall away here rather than in the cutting below). A candidate
whose swept segment over that hull then misses the *holding region* of its lane or shoulder
(:func:`_holders`: every point whose direction Scenic's rules read off that centreline; in an
intersection area, where the lanes overlap, only the part no lane listed before it covers) is
dropped too: most of the reach's candidates near an intersection, and beside a lane of the
other direction, are of that kind, and each costs the cutting below far more than this test.

Why the preimage holds every walk ending at E (the invariant a refutation rests on): take a walk
from X for D with headings h_0 .. h_{n-1} and points p_0 = X .. p_n = E. Going back from p_{k+1},
the segment that gives p_k its heading lies within its reach of p_k, and p_k within |D| / n of
p_{k+1}, so h_k is among the candidates, and p_k = E + D b_k lies on the branch's swept segment
for that D, and in the holding region of that segment's centreline (so that swept segment meets
it). The field at p_k is h_k, and the D sub-interval holding D is one on which the field
does not change: it changes only (i) across an area boundary (a lane, intersection or shoulder,
and the 5 cm bands around them), which decides the rule that applies, or (ii) within one lane,
where its nearest centreline segment changes: at a vertex line between adjacent segments that
turn by less than 90°, or where two segments between which the centreline turns by more than 90°
(adjacent or not: a lane section folding back joins two almost opposite adjacent segments, whose
equally-near set no vertex line marks) are equally near; all are cuts (:func:`.follow_pieces.crossings`).
So the midpoint reads h_k. Left out: D exactly at a cut (a finite set, read as a neighbour),
and the nearest-lane rule (in an intersection area between its lanes, within 5 cm of a lane),
assumed not to change inside a sub-interval. tests/scene/test_follow_start.py walks random
Town01 starts forward and finds each in the preimage of its end; before adjacent folds were
pairs, one of 360 (and of 300) was missing, since then none of 3,600 (D in [-30, 30]).
Only the changes to or from the heading tried are cut: a vertex line changes it only between
its two segments' headings, a tie only between its pair's.

The preimage is that of one point E (the caller's end box's centre): a walk that ends in the
box but not at E is not in it.

With ``check_first=False`` the first heading h_0 is not checked against the field along X's
segment: the caller checks it at the start it picks (a start on a curb lies on the linework, where
the heading read inside a sub-interval need not be the one at the start itself); nor is it
tried against the holding regions (the caller walks every start again, and those rows stay the
reach's).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import shapely

from ..model.polylines import Polylines
from ._reach import narrow
from .clip import clipped
from .follow_pieces import DEGENERATE_M, _by_step_count, _Columns, _split, linework
from .geometry import ELEMENT_REACH_M, MapGeometry
from .regions import Field

REACH_MARGIN_M = 0.25
"""Added to the farthest distance at which a centreline segment may give a point its heading."""

FOOT_SLACK_M = 1e-3
"""How far a point may lie before a segment's start (or past its end), along it and along the
segment before (after) it, and still count as nearest to it (metres): wide enough that rounding in
the projection that picks the nearest segment cannot lose one (a point that far past a vertex
along both segments, the next one at least :data:`NEIGHBOUR_M` long, lies at least 5e-8 m nearer
the next one within 10 m, against rounding below 1e-10 m)."""

NEIGHBOUR_M = 0.01
"""A neighbouring segment shorter than this (metres) is not used to narrow a segment's D
interval (too short to be surely nearer by more than rounding)."""


HOLD_BAND_M = 0.06
"""The band around a lane (and its intersection areas) or a shoulder in which a point in no lane may
take its direction (metres): Scenic's tolerance (:data:`~.geometry.ELEMENT_REACH_M`, 0.05) and
room for the buffer's chords (1.2 mm at 0.06 m)."""

HOLD_SLACK_M = 1e-6
"""How far the holding regions are grown (metres: slack for rounding; at least 0.98 of it where the
buffer's chords cut its round corners): a swept segment that meets the grown region keeps its
heading."""


DOMAIN_SLACK_M = 1e-6
"""Slack on the reach of a branch's remaining steps towards the start's domain (metres)."""


@dataclass
class Inverse:
    """Per map: every centreline segment (lanes, then shoulders): an R-tree of the boxes within
    its reach, its heading (radians) with the step direction ``u(h) = (-sin h, cos h)``'s
    negation (``step``: rows of sin h, -cos h, what a step back along it adds per metre of D),
    its ends (rows of x0, y0, x1, y1), its reach (metres: no point farther from it takes its
    heading), the box within its reach (``near``: rows of x_lo, y_lo, x_hi, y_hi), its unit
    direction and those of the segments before and after it on its centreline (rows of x, y; NaN:
    none, or shorter than :data:`NEIGHBOUR_M`), and its centreline (``owner``: an index into
    ``holds``, a region per lane, then per shoulder, holding every point whose direction Scenic
    reads off that centreline: :func:`_holders`); and the union of the lanes, intersection areas
    and shoulders (off which a point may take heading 0)."""

    tree: shapely.STRtree
    heading: np.ndarray
    step: np.ndarray
    ends: np.ndarray
    reach: np.ndarray
    near: np.ndarray
    unit: np.ndarray
    before: np.ndarray
    after: np.ndarray
    owner: np.ndarray
    holds: np.ndarray
    roads: shapely.Geometry


@dataclass
class Preimage(_Columns):
    """Walks ending at E[row]: for every D in [lo, hi] the start ``X = E + D (ax, ay)`` walks to E
    in ``steps`` steps; ``first`` is the first step's heading when it is still to be checked at X
    (NaN when it was checked along the segment)."""

    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    steps: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    first: np.ndarray


@dataclass
class _Back(_Columns):
    """Walks under backward enumeration: the point reached so far is ``E[row] + D (ax, ay)`` for D
    in [lo, hi], ``left`` steps before it still to choose, ``first`` as in :class:`Preimage`."""

    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    steps: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    left: np.ndarray
    first: np.ndarray


def inverse(geometry: MapGeometry) -> Inverse:
    """The map's centreline segments for candidate headings, built once per geometry."""
    found = _INVERSE.get(geometry)
    if found is None:
        found = _INVERSE[geometry] = _build_inverse(geometry)
    return found


def _build_inverse(geometry: MapGeometry) -> Inverse:
    road_map = geometry._require_map()
    lines = road_map.centreline_polylines
    owner = np.repeat(np.arange(len(lines)), lines.count)
    lane_reach = _reach(road_map.lane_polygons, lines)[owner]
    reach = lane_reach + ELEMENT_REACH_M
    lanes = shapely.union_all(road_map.lane_polygons) if len(road_map.lanes) else shapely.Polygon()
    index = road_map.lane_index
    for area in road_map.intersections:
        outside = shapely.difference(area.polygon, lanes)
        if outside.is_empty:
            continue
        coords = shapely.get_coordinates(shapely.segmentize(outside, 0.25))
        gap = float(np.max(shapely.distance(shapely.points(coords), lanes), initial=0.0)) + 0.25
        inside = np.isin(owner, [index[lane] for lane in area.lanes if lane in index])
        reach[inside] = np.maximum(reach[inside], lane_reach[inside] + gap)
    centres, reaches, owners = [lines], [reach], [owner]
    with_shoulders = bool(road_map.shoulders) and all(a.centreline is not None for a in road_map.shoulders)
    if with_shoulders:
        shoulders = Polylines([a.centreline for a in road_map.shoulders])
        areas = np.array([a.polygon for a in road_map.shoulders], dtype=object)
        owner = np.repeat(np.arange(len(shoulders)), shoulders.count)
        centres.append(shoulders)
        reaches.append(_reach(areas, shoulders)[owner] + ELEMENT_REACH_M)
        owners.append(len(lines) + owner)
    start = np.concatenate([c.start for c in centres])
    end = np.concatenate([c.end for c in centres])
    heading = np.concatenate([c.heading for c in centres])
    unit, before, after = (np.concatenate(parts) for parts in zip(*(_neighbours(c) for c in centres)))
    reach = np.concatenate(reaches) + REACH_MARGIN_M
    low, high = np.minimum(start, end) - reach[:, None], np.maximum(start, end) + reach[:, None]
    near = shapely.box(low[:, 0], low[:, 1], high[:, 0], high[:, 1])
    areas = [lanes] + [a.polygon for a in road_map.intersections] + [a.polygon for a in road_map.shoulders]
    roads = shapely.union_all(areas)
    shapely.prepare(roads)
    ends = np.concatenate([start, end], axis=1)
    step = np.stack([np.sin(heading), -np.cos(heading)], axis=1)
    boxes = np.concatenate([low, high], axis=1)
    holds = _holders(road_map, with_shoulders)
    owner = np.concatenate(owners)
    return Inverse(shapely.STRtree(near), heading, step, ends, reach, boxes, unit, before, after, owner, holds, roads)


def _holders(road_map, with_shoulders: bool) -> np.ndarray:
    """Per lane (then per shoulder, ``with_shoulders``): a region (prepared, grown by
    :data:`HOLD_SLACK_M`) holding every point whose road direction
    :meth:`~.geometry.MapGeometry.scenic_headings` reads off its centreline.
    A point of an intersection area with lanes takes the first of its lanes (in the area's order)
    holding it, else the nearest of them; a point in no such area the first lane holding it; a
    point in no lane and no such area a shoulder holding it, else the nearest lane of an area
    within Scenic's tolerance, else the nearest lane or the first shoulder within it. So a lane
    holds: in each area listing it, its part that no lane listed before it covers, the area's
    part outside its lanes, and the rim of :data:`HOLD_BAND_M` around the area; itself outside
    those areas (inside areas without lanes too); and the rim of :data:`HOLD_BAND_M` around
    itself. A shoulder holds itself and the rim around it. (The rims may reach into other lanes,
    where those lanes' directions count instead: a few more candidates, for no overlay with
    every lane near each.)"""
    polygons = road_map.lane_polygons
    index = road_map.lane_index
    areas = road_map.intersections
    listed = [[index[lane] for lane in a.lanes if lane in index] for a in areas]
    bare = shapely.union_all([a.polygon for a, lanes in zip(areas, listed) if not lanes])
    outer = [
        shapely.union_all([shapely.difference(a.polygon, shapely.union_all(polygons[lanes])), _rim(a.polygon)])
        for a, lanes in zip(areas, listed)
    ]
    holds = []
    for k in range(len(polygons)):
        parts, own = [_rim(polygons[k])], []
        for a, lanes, rest in zip(areas, listed, outer):
            if k not in lanes:
                continue
            first = shapely.intersection(polygons[k], a.polygon)
            parts += [shapely.difference(first, shapely.union_all(polygons[lanes[: lanes.index(k)]])), rest]
            own.append(a.polygon)
        parts.append(shapely.difference(polygons[k], shapely.difference(shapely.union_all(own), bare)))
        holds.append(shapely.union_all(parts))
    if with_shoulders:
        holds += [shapely.buffer(a.polygon, HOLD_BAND_M) for a in road_map.shoulders]
    found = shapely.buffer(np.array(holds, dtype=object), HOLD_SLACK_M)
    shapely.prepare(found)
    return found


def _rim(polygon: shapely.Geometry) -> shapely.Geometry:
    """The band of :data:`HOLD_BAND_M` around a polygon, outside it."""
    return shapely.difference(shapely.buffer(polygon, HOLD_BAND_M), polygon)


def _neighbours(lines: Polylines) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each segment's unit direction and those of the segments before and after it on its polyline
    (NaN rows: none, or shorter than :data:`NEIGHBOUR_M`)."""
    w = lines.end - lines.start
    length = np.hypot(w[:, 0], w[:, 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = w / length[:, None]
    usable = np.where((length >= NEIGHBOUR_M)[:, None], unit, np.nan)
    owner = np.repeat(np.arange(len(lines)), lines.count)
    index = np.arange(len(owner))
    first = index == lines.first[owner]
    last = index == lines.last[owner]
    before = np.where(first[:, None], np.nan, np.roll(usable, 1, axis=0))
    after = np.where(last[:, None], np.nan, np.roll(usable, -1, axis=0))
    return unit, before, after


def _reach(polygons: np.ndarray, lines: Polylines) -> np.ndarray:
    """How far each polygon's farthest point lies from its centreline (metres, boundaries densified)."""
    return shapely.hausdorff_distance(shapely.boundary(polygons), lines.geometries, densify=0.1)


def preimages(
    geometry: MapGeometry,
    field: Field,
    ex: np.ndarray,
    ey: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    check_first: bool = True,
    domain: np.ndarray | None = None,
) -> Preimage:
    """The preimage (see the module docstring) of each point (ex[i], ey[i]) for D in [lo[i], hi[i]]
    (metres, finite, lo <= hi). With ``domain`` (a shapely geometry per point: where the start
    must lie), only the walks that may start there: a branch whose point is farther from the
    domain than its remaining steps can go (each ``|D| / n`` long) is dropped."""
    lw, inv = linework(geometry), inverse(geometry)
    ex, ey = np.asarray(ex, dtype=float), np.asarray(ey, dtype=float)
    start = _by_step_count(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float))
    n = len(start.row)
    b = _Back(start.row, start.lo, start.hi, start.steps, start.ax, start.ay, start.steps.copy(), np.full(n, np.nan))
    done = []
    while len(b.row):
        last = b.left == 1
        moved = _candidates(inv, ex, ey, b, ~last | check_first)
        if domain is not None and not (check_first and not moved.left.any()):
            # not when every branch has reached its start and check_first: _clipped below drops
            # each sub-interval whose swept segment misses the domain, so every one this would drop
            moved = moved.take(np.flatnonzero(_may_start(ex, ey, moved.branches, domain)))
        if check_first:
            moved = _consistent(geometry, field, lw, ex, ey, moved)
            if domain is not None:
                moved = _clipped(ex, ey, moved, domain)
        else:
            keep = moved.take(np.flatnonzero(~last[moved.parent]))
            first = moved.take(np.flatnonzero(last[moved.parent]))
            done.append(first.branches)
            moved = _consistent(geometry, field, lw, ex, ey, keep) if len(keep.parent) else keep
        finished = moved.left == 0
        done.append(moved.branches.take(np.flatnonzero(finished)))
        b = moved.branches.take(np.flatnonzero(~finished))
    found = _concat(done) if done else b
    return Preimage(found.row, found.lo, found.hi, found.steps, found.ax, found.ay, found.first)


@dataclass
class _Moved:
    """Branches one step further back, each with its heading and the index of its parent branch."""

    branches: _Back
    heading: np.ndarray
    parent: np.ndarray

    @property
    def left(self) -> np.ndarray:
        return self.branches.left

    def take(self, index: np.ndarray) -> _Moved:
        return _Moved(self.branches.take(index), self.heading[index], self.parent[index])


def _may_start(ex, ey, b: _Back, domain: np.ndarray) -> np.ndarray:
    """Whether each branch's point, swept over its D interval, lies within its remaining steps of
    its row's domain."""
    p = np.stack([ex[b.row] + b.lo * b.ax, ey[b.row] + b.lo * b.ay], axis=1)
    q = np.stack([ex[b.row] + b.hi * b.ax, ey[b.row] + b.hi * b.ay], axis=1)
    reach = b.left * np.maximum(np.abs(b.lo), np.abs(b.hi)) / b.steps + DOMAIN_SLACK_M
    return shapely.dwithin(shapely.linestrings(np.stack([p, q], axis=1)), domain[b.row], reach)


def _clipped(ex, ey, moved: _Moved, domain: np.ndarray) -> _Moved:
    """The branches with no step left, their D intervals narrowed to the hull of the D whose start
    lies in the domain (those with none dropped). Called after :func:`_consistent`, on the few
    sub-intervals whose first heading holds (intersecting a swept segment with a region is the
    dearest operation here)."""
    b = moved.branches
    last = np.flatnonzero(b.left == 0)
    if not len(last):
        return moved
    p = np.stack([ex[b.row[last]] + b.lo[last] * b.ax[last], ey[b.row[last]] + b.lo[last] * b.ay[last]], axis=1)
    q = np.stack([ex[b.row[last]] + b.hi[last] * b.ax[last], ey[b.row[last]] + b.hi[last] * b.ay[last]], axis=1)
    r = q - p
    rr = np.einsum("ij,ij->i", r, r)
    inside = clipped(shapely.linestrings(np.stack([p, q], axis=1)), domain[b.row[last]])
    coords, owner = shapely.get_coordinates(inside, return_index=True)
    t = np.einsum("ij,ij->i", coords - p[owner], r[owner]) / np.maximum(rr[owner], 1e-300)
    t_lo, t_hi = np.full(len(last), np.inf), np.full(len(last), -np.inf)
    np.minimum.at(t_lo, owner, t)
    np.maximum.at(t_hi, owner, t)
    still = rr <= DEGENERATE_M**2
    t_lo, t_hi = np.where(still & (t_lo <= t_hi), 0.0, np.clip(t_lo, 0, 1)), np.where(still, 1.0, np.clip(t_hi, 0, 1))
    width = b.hi[last] - b.lo[last]
    b.lo[last], b.hi[last] = b.lo[last] + t_lo * width, b.lo[last] + t_hi * width
    keep = np.ones(len(b.row), dtype=bool)
    keep[last] = np.isfinite(t_lo) & (t_lo <= t_hi)
    return moved.take(np.flatnonzero(keep))


def _candidates(inv: Inverse, ex, ey, b: _Back, held: np.ndarray) -> _Moved:
    """Each branch one step back along every heading a centreline segment near it has, its D
    interval narrowed to where the new point stays within the segment's reach (the hull over the
    segments sharing a heading), and along heading 0 where the new point may leave the road. For
    the branches marked ``held``, a segment's heading is tried only where the new point may lie in
    its centreline's holding region (:func:`_holders`)."""
    x, y = ex[b.row], ey[b.row]
    px, qx = x + b.lo * b.ax, x + b.hi * b.ax
    py, qy = y + b.lo * b.ay, y + b.hi * b.ay
    grow = np.maximum(np.abs(b.lo), np.abs(b.hi)) / b.steps
    boxes = shapely.box(
        np.minimum(px, qx) - grow, np.minimum(py, qy) - grow, np.maximum(px, qx) + grow, np.maximum(py, qy) + grow
    )
    near, segment = inv.tree.query(boxes)
    steps = b.steps[near]
    step = inv.step.take(segment, axis=0)
    ax = np.concatenate([b.ax.take(near) + step[:, 0] / steps, b.ax + 0.0])
    ay = np.concatenate([b.ay.take(near) + step[:, 1] / steps, b.ay + -1.0 / b.steps])
    branch = np.concatenate([near, np.arange(len(b.row))])
    heading = np.concatenate([inv.heading.take(segment), np.zeros(len(b.row))])
    lo, hi = _within(inv, x[branch], y[branch], b.lo[branch], b.hi[branch], ax, ay, segment, held[near])
    keep = np.flatnonzero(lo <= hi)
    order = keep[np.lexsort((heading[keep], branch[keep]))]
    branch, heading = branch[order], heading[order]
    new = np.ones(len(branch), dtype=bool)
    new[1:] = (branch[1:] != branch[:-1]) | (heading[1:] != heading[:-1])
    starts = np.flatnonzero(new)
    moved = b.take(branch[starts])
    moved.lo, moved.hi = np.minimum.reduceat(lo[order], starts), np.maximum.reduceat(hi[order], starts)
    moved.ax, moved.ay = ax[order[starts]], ay[order[starts]]
    moved.left = moved.left - 1
    heading = heading[starts]
    moved.first = np.where(moved.left == 0, heading, np.nan)
    return _Moved(moved, heading, branch[starts])


def _within(inv: Inverse, x, y, lo, hi, ax, ay, segment, held) -> tuple[np.ndarray, np.ndarray]:
    """The D interval (lo > hi: none) on which the point ``(x, y) + D (ax, ay)`` (row i, D in
    [lo[i], hi[i]]) comes within its reach of the segment ``segment[i]`` of ``inv`` where its
    centreline's nearest point may lie on that segment (:func:`_narrowed`), as the hull of that
    set, dropped where ``held[i]`` and that part of the swept segment misses the centreline's
    holding region; for the rows past ``segment`` (heading 0), where it may leave the roads. Rows whose
    swept segment misses the box within the segment's reach are dropped before the exact test
    (most of them: the R-tree's query box is a whole step wide in every direction)."""
    px, qx = x + lo * ax, x + hi * ax
    py, qy = y + lo * ay, y + hi * ay
    n = len(segment)
    start, end = np.full(len(px), np.inf), np.full(len(px), -np.inf)
    zero = shapely.linestrings(np.stack([px[n:], py[n:], qx[n:], qy[n:]], axis=1).reshape(-1, 2, 2))
    off = n + np.flatnonzero(~shapely.covers(inv.roads, zero))
    start[off], end[off] = lo[off], hi[off]
    box = inv.near.take(segment, axis=0)
    meet = np.flatnonzero(
        (np.minimum(px[:n], qx[:n]) <= box[:, 2])
        & (np.maximum(px[:n], qx[:n]) >= box[:, 0])
        & (np.minimum(py[:n], qy[:n]) <= box[:, 3])
        & (np.maximum(py[:n], qy[:n]) >= box[:, 1])
    )
    p = np.stack([px[meet], py[meet]], axis=1)
    r = np.stack([qx[meet], qy[meet]], axis=1) - p
    s = segment[meet]
    ends = inv.ends.take(s, axis=0)
    unit, before, after = (v.take(s, axis=0) for v in (inv.unit, inv.before, inv.after))
    t_lo, t_hi = _narrowed(p, r, ends[:, :2], ends[:, 2:], inv.reach.take(s), unit, before, after)
    hit = meet[t_lo <= t_hi]  # elsewhere t_hi may be -inf, and -inf * 0 (a point interval) is NaN
    t_lo, t_hi = t_lo[t_lo <= t_hi], t_hi[t_lo <= t_hi]
    width = hi[hit] - lo[hit]
    start[hit], end[hit] = lo[hit] + t_lo * width, lo[hit] + t_hi * width
    test = hit[held[hit]]
    swept = np.stack([x[test] + start[test] * ax[test], y[test] + start[test] * ay[test]], axis=1)
    swept = np.stack([swept, np.stack([x[test] + end[test] * ax[test], y[test] + end[test] * ay[test]], axis=1)], 1)
    away = test[~shapely.intersects(inv.holds[inv.owner[segment[test]]], shapely.linestrings(swept))]
    start[away], end[away] = np.inf, -np.inf
    return start, end


def _narrowed(p, r, a, z, radius, unit, before, after, nearest: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """The hull [t_lo, t_hi] (t_lo > t_hi: empty) of the t in [0, 1] at which p + t r lies within
    ``radius`` of the segment a-z (the union of the band along it and the discs at its ends: an
    infinite radius gives [0, 1]); with ``nearest``, narrowed to the hull of the t at which the
    nearest point of its centreline may lie on that segment (``unit``: its direction): dropped
    are the t at which the point lies :data:`FOOT_SLACK_M` or more before a along it and along
    the segment before (``before``: its direction; NaN: none), whose end is then nearer, and
    likewise past z along it and the segment after (``after``): each end's forbidden interval
    is where both hold (two linear bounds), and the hull's ends are moved past them twice.
    Rows are numpy float64 arrays (points and directions (m, 2), ``radius`` (m,)); one C pass
    (:mod:`._reach`; its numpy formulas, bit for bit)."""
    low, high = np.empty(len(p)), np.empty(len(p))
    rows = (p, r, a, z, radius, unit, before, after)
    narrow(*(np.ascontiguousarray(v, dtype=float) for v in rows), _CONSTANTS, nearest, low, high)
    return low, high


_CONSTANTS = (DEGENERATE_M**2, FOOT_SLACK_M)
"""What :func:`_narrowed`'s C pass takes as given: a swept segment whose squared length is at most
the first does not move; the foot slack (metres)."""


def _consistent(geometry: MapGeometry, field: Field, lw, ex, ey, moved: _Moved) -> _Moved:
    """The D sub-intervals on which the field at each branch's new point takes its heading."""
    b = moved.branches
    branch, low, high = _split(lw, ex, ey, b, moved.heading)
    mid = (low + high) / 2
    at = geometry.scenic_headings(
        field, ex[b.row[branch]] + mid * b.ax[branch], ey[b.row[branch]] + mid * b.ay[branch], _no_terms
    )
    keep = at == moved.heading[branch]
    branch, low, high = _joined(branch[keep], low[keep], high[keep])
    found = moved.take(branch)
    found.branches.lo, found.branches.hi = low, high
    found.branches.first = np.full(len(branch), np.nan)
    return found


def _joined(branch, low, high):
    """Neighbouring kept sub-intervals of one branch joined (they share an end)."""
    if not len(branch):
        return branch, low, high
    new = np.ones(len(branch), dtype=bool)
    new[1:] = (branch[1:] != branch[:-1]) | (low[1:] != high[:-1])
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], len(branch)) - 1
    return branch[starts], low[starts], high[ends]


def _concat(parts: list[_Back]) -> _Back:
    names = ("row", "lo", "hi", "steps", "ax", "ay", "left", "first")
    return _Back(*(np.concatenate([getattr(p, k) for p in parts]) for k in names))


def _no_terms(term):
    raise ValueError(f"roadDirection has no parameters, got {term!r}")


_INVERSE: weakref.WeakKeyDictionary[MapGeometry, Inverse] = weakref.WeakKeyDictionary()
