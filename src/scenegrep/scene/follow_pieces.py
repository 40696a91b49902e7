"""Every walk ``follow roadDirection from X for D`` can take, for a known start X and D in an interval.

Scenic 3.1.1's ``VectorField.followFrom(X, D)`` (the ``follow`` operator and the ``following``
specifier) takes ``n = max(4, ceil(D / 5))`` forward Euler steps of ``D / n`` metres; step k
goes along the field's heading h_k at the point reached so far (heading 0 = +y, counter-clockwise,
radians), so the end is ``X + D * a`` with ``a = (1/n) * sum_k (-sin h_k, cos h_k)``, and the
object's heading is the field at the end. Headings are those of :mod:`.geometry`
(:meth:`~.geometry.MapGeometry.scenic_headings` for the steps, every value of
:meth:`~.geometry.MapGeometry.field_values` at the end).

The field ``roadDirection`` is piecewise constant: a point takes the heading of one centreline
segment of the lane (or intersection lane) holding it, off the lanes of a shoulder's centreline,
or of the element within Scenic's 5 cm tolerance, or 0. The heading can only change where a
point crosses the *linework*: a lane, intersection or shoulder boundary, or the boundary of the
band within 5 cm of the lanes, of the intersections or of the shoulders (buffers of their unions);
at each interior vertex of a centreline (a lane's or a shoulder's), its two segment normals and
their bisector (where the projection onto the centreline passes the vertex or jumps across the
inner side), reaching 1 m beyond the lane or shoulder;
or, where a centreline turns by more than 90° within twice its reach (the lane's half width
plus 1 m; folds where lane sections join, sharp bends), a point equally near two segments (also
adjacent ones: a fold joins two almost opposite ones, whose vertex lines miss where they are
equally near) and nearer than the rest (roots of a difference of squared distances, piecewise
quadratic in D). For a
fixed step count and a fixed sequence of headings every point of the walk is affine in D, so
the points of step k sweep a segment as D runs over an interval; cutting that segment where it
crosses the linework gives sub-intervals of D on which h_k is constant (read at their
midpoints). Doing this step by step partitions the D interval into *pieces* — D intervals with
one heading sequence, hence one end ``X + D * a`` and one end heading — at most one piece per
crossing plus one per step count: the enumeration is exact and bounded, not a sample. Given the
box the end must reach (the label and its tolerance), a branch is dropped as soon as its
remaining steps (each ``|D| / n`` long) cannot bring it there.

Exact up to the boundaries between pieces (D values where a walk point lies on the linework,
a finite set), with two assumptions: centreline segments other than neighbours compete only across a
turn of more than 90° (true when the centreline's radius of curvature exceeds the lane's half
width; tests walk Town01 and Town06 at random against the step-by-step walk); and where a point
lies in no lane but inside an intersection area or within 5 cm of a lane or intersection, or
(for the end heading) off every lane, the *nearest* lane's direction is read at the piece's
midpoint, i.e. the nearest lane is assumed not to change inside a piece (shoulder centrelines,
too, are assumed not to fold; the 5 cm bands are shapely's buffers, polygons within 0.1 mm of
Scenic's round ones).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, fields
from functools import cache
from typing import Self

import numpy as np
import shapely

from .follow import MIN_STEPS, STEP_M, steps_for
from ..model.polylines import Polylines
from .geometry import ELEMENT_REACH_M, MapGeometry
from .heading_index import HeadingIndex, heading_index, near_heading
from .regions import Field

REACH_MARGIN_M = 1.0
"""How far a vertex line reaches beyond the farthest point of its lane from the centreline."""

DEGENERATE_M = 1e-12
"""A swept segment shorter than this is a point: it crosses nothing."""

TIE_M = 1e-7
"""Two competing segments' equal distance counts as the nearest distance within this (metres)."""

TURN_RAD = np.pi / 2
"""Centreline segments (neighbours too) compete for points of their lane only where the centreline
turns by more than this between them (folds where pieces of a lane join, sharp bends); elsewhere
the nearest segment changes at a vertex line."""

ONLY_RAD = 1e-6
"""With a heading to cut for (:func:`crossings`), pairs of segments whose headings are farther
from it than this (radians) are not looked at."""

SLACK = 1e-9
"""Slack on a foot-of-perpendicular parameter when checking which distance piece holds."""

PIECE_RANGE = np.array([[-np.inf, SLACK], [-SLACK, 1 + SLACK], [1 - SLACK, np.inf]])
"""The range of the foot parameter in each distance piece (nearest to the start vertex, to the
interior, to the end vertex), with slack."""


@dataclass
class Linework:
    """Where ``roadDirection`` may change (see the module docstring): segments with an R-tree, and
    pairs of centreline segments of one lane that may compete for a point (``pair_lane``: their
    lane; ``pair_reach``: its reach plus the margin), with an R-tree of the boxes where they may
    (within the lane's reach of both); the centreline polylines; an R-tree of where a lane's
    direction may count at all (each lane grown by Scenic's tolerance, and the intersection areas,
    where the nearest lane may count). For cuts for one heading (:func:`crossings` with ``only``):
    the lines and the pairs in one heading index (items 0 .. len(start) - 1 the lines: the area
    boundaries for every heading, the vertex lines by the headings of the segments either side,
    between which alone the heading may change there; then the pairs, by their two segments'
    headings), so that one lookup finds all three."""

    start: np.ndarray
    end: np.ndarray
    tree: shapely.STRtree
    pairs: np.ndarray
    pair_lane: np.ndarray
    pair_reach: np.ndarray
    pair_tree: shapely.STRtree
    polylines: Polylines
    lane_reach: shapely.STRtree
    heading_items: HeadingIndex


class _Columns:
    """Equal-length numpy columns (the dataclass's fields) whose rows are taken together."""

    def take(self, index: np.ndarray) -> Self:
        """The rows at ``index``, as a new instance of the same class."""
        return type(self)(*(getattr(self, name)[index] for name in _names(type(self))))


@cache
def _names(kind: type) -> tuple[str, ...]:
    """The field names of a dataclass, in order."""
    return tuple(f.name for f in fields(kind))


@dataclass
class Pieces(_Columns):
    """D intervals with one heading sequence: for start ``row``, every D in [lo, hi] ends the walk
    at ``start + D * (ax, ay)`` with the field taking ``heading`` there (a row per possible value)."""

    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    heading: np.ndarray


def linework(geometry: MapGeometry) -> Linework:
    """The map's linework, built once per geometry."""
    found = _LINEWORK.get(geometry)
    if found is None:
        found = _LINEWORK[geometry] = _build_linework(geometry)
    return found


def _build_linework(geometry: MapGeometry) -> Linework:
    road_map = geometry._require_map()
    shoulders = [a.polygon for a in road_map.shoulders]
    intersections = [a.polygon for a in road_map.intersections]
    areas = list(road_map.lane_polygons) + intersections + shoulders
    bands = [list(road_map.lane_polygons), intersections, shoulders]
    areas += [shapely.buffer(shapely.union_all(band), ELEMENT_REACH_M) for band in bands if band]
    starts, ends, sides = [np.zeros((0, 2))], [np.zeros((0, 2))], [np.zeros((0, 2))]
    for ring in shapely.get_rings(shapely.get_parts(np.array(areas, dtype=object))):
        coords = shapely.get_coordinates(ring)
        starts.append(coords[:-1])
        ends.append(coords[1:])
        sides.append(np.full((len(coords) - 1, 2), np.nan))
    polylines = road_map.centreline_polylines
    reach = shapely.hausdorff_distance(shapely.boundary(road_map.lane_polygons), polylines.geometries)
    lines = [(polylines, k, r) for k, r in enumerate((reach + REACH_MARGIN_M).tolist())]
    if all(a.centreline is not None for a in road_map.shoulders):
        centres = Polylines([a.centreline for a in road_map.shoulders])
        near = shapely.hausdorff_distance(shapely.boundary(np.array(shoulders, dtype=object)), centres.geometries)
        lines += [(centres, k, r) for k, r in enumerate((near + REACH_MARGIN_M).tolist())]
    for owner, k, length in lines:
        vertex_starts, vertex_ends = _vertex_lines(owner.lines[k], length)
        starts.append(vertex_starts)
        ends.append(vertex_ends)
        heading = owner.heading[owner.first[k] : owner.first[k] + owner.count[k]]
        sides.append(np.tile(np.stack([heading[:-1], heading[1:]], axis=1), (3, 1)))
    start, end, side = np.concatenate(starts), np.concatenate(ends), np.concatenate(sides)
    keep = np.any(start != end, axis=1)
    start, end, side = start[keep], end[keep], side[keep]
    tree = shapely.STRtree(shapely.linestrings(np.stack([start, end], axis=1)))
    pairs, lanes, boxes = _competing_pairs(polylines, reach)
    near = reach[lanes] + REACH_MARGIN_M
    lane_reach = shapely.STRtree(np.append(shapely.buffer(road_map.lane_polygons, ELEMENT_REACH_M), intersections))
    heading_items = heading_index(
        np.concatenate([side, polylines.heading[pairs].reshape(-1, 2)]),
        np.concatenate([shapely.bounds(tree.geometries), shapely.bounds(boxes).reshape(-1, 4)]),
        np.concatenate([np.isnan(side[:, 0]), np.zeros(len(pairs), dtype=bool)]),
    )
    return Linework(
        start,
        end,
        tree,
        pairs,
        lanes,
        near,
        shapely.STRtree(boxes),
        polylines,
        lane_reach,
        heading_items,
    )


def _competing_pairs(polylines: Polylines, reach: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Segment pairs (i < j, flat indices) of one centreline turning by more than TURN_RAD from one
    to the other (a fold between neighbours included) within twice the
    lane's reach of each other, their lane, and the box of points within reach of both."""
    segments = shapely.linestrings(np.stack([polylines.start, polylines.end], axis=1))
    owner = np.repeat(np.arange(len(polylines)), polylines.count)
    near = reach[owner] + REACH_MARGIN_M
    i, j = shapely.STRtree(segments).query(segments, predicate="dwithin", distance=2 * near.max(initial=0.0))
    turned = np.concatenate([[0.0], np.cumsum(np.abs(_wrap(np.diff(polylines.heading))))])
    keep = (j > i) & (owner[i] == owner[j])
    i, j = i[keep], j[keep]
    keep = turned[j] - turned[i] > TURN_RAD
    i, j = i[keep], j[keep]
    keep = shapely.distance(segments[i], segments[j]) <= 2 * near[i]
    i, j = i[keep], j[keep]
    lo = np.maximum(np.minimum(polylines.start[i], polylines.end[i]), np.minimum(polylines.start[j], polylines.end[j]))
    hi = np.minimum(np.maximum(polylines.start[i], polylines.end[i]), np.maximum(polylines.start[j], polylines.end[j]))
    r = near[i][:, None]
    boxes = shapely.box(*(lo - r).T, *(hi + r).T)
    return np.stack([i, j], axis=1), owner[i], boxes


def _vertex_lines(vertices: np.ndarray, length: float) -> tuple[np.ndarray, np.ndarray]:
    """At each interior vertex of a polyline: the normals of its two segments and their bisector,
    ``length`` each side."""
    if len(vertices) < 3:
        return np.zeros((0, 2)), np.zeros((0, 2))
    direction = np.diff(vertices, axis=0)
    direction /= np.hypot(direction[:, 0], direction[:, 1])[:, None]
    normal = np.stack([-direction[:, 1], direction[:, 0]], axis=1)
    before, after = normal[:-1], normal[1:]
    bisector = before + after
    size = np.hypot(bisector[:, 0], bisector[:, 1])[:, None]
    bisector = np.where(size > 1e-9, bisector / np.maximum(size, 1e-300), direction[:-1])
    vertex = vertices[1:-1]
    lines = np.concatenate([before, after, bisector])
    centre = np.concatenate([vertex, vertex, vertex])
    return centre - length * lines, centre + length * lines


def crossings(lw: Linework, px, py, qx, qy, only=None) -> tuple[np.ndarray, np.ndarray]:
    """(segment index, parameter t in (0, 1)) where segment i from p_i to q_i crosses the linework
    (for a stretch of linework along the segment, both ends of the overlap), or where two
    competing centreline segments become equally near along it (with ``only``, a heading per
    segment: only pairs one of whose segments has that heading, the changes to or from it)."""
    moving = np.hypot(qx - px, qy - py) > DEGENERATE_M
    index = np.flatnonzero(moving)
    if not len(index):
        return np.zeros(0, np.intp), np.zeros(0)
    p = np.stack([px, py], 1).take(index, axis=0)
    r = np.stack([qx, qy], 1).take(index, axis=0) - p
    if only is None:
        segments = shapely.linestrings(np.stack([p, p + r], axis=1))
        walk, line = lw.tree.query(segments)
        pair_walk, pair = lw.pair_tree.query(segments)
    else:
        walk, line, pair_walk, pair = _near_only(lw, p, r, np.asarray(only)[index])
    start = lw.start.take(line, axis=0)
    found_walk, found_t = _segment_crossings(
        p.take(walk, axis=0), r.take(walk, axis=0), start, lw.end.take(line, axis=0) - start
    )
    tie_walk, tie_t, _ = _ties(lw, p, r, pair_walk, pair)
    found_walk = np.concatenate([walk[found_walk], tie_walk])
    found_t = np.concatenate([found_t, tie_t])
    inside = (found_t > 0) & (found_t < 1)
    return index[found_walk[inside]], found_t[inside]


def _near_only(lw: Linework, p, r, only) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(segment index, line index) of the linework lines and (segment index, pair index) of the
    competing pairs whose boxes meet segment i's (as the R-tree finds them) and that may change the
    heading to or from ``only[i]``: every area boundary, the vertex lines with a segment of that
    heading either side, and the pairs one of whose segments has it (one heading-index lookup for
    all three)."""
    walk, item = near_heading(lw.heading_items, only, _bounds(p, r), ONLY_RAD)
    lines = item < len(lw.start)
    return walk[lines], item[lines], walk[~lines], item[~lines] - len(lw.start)


def _bounds(p: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The boxes (rows of x_min, y_min, x_max, y_max) of the segments from p to p + r."""
    return np.concatenate([np.minimum(p, p + r), np.maximum(p, p + r)], axis=1)


def ties(lw: Linework, start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(segment index, flat index of a centreline segment) pairs: along the segment from
    ``start[i]`` to ``end[i]`` (rows of x, y; metres) that centreline segment and a competing one
    (both given) become equally near strictly inside, where the heading may change along a curve
    rather than at the straight linework."""
    r = end - start
    moving = np.flatnonzero(np.hypot(r[:, 0], r[:, 1]) > DEGENERATE_M)
    p, r = start[moving], r[moving]
    walk, t, pair = _ties(lw, p, r, *lw.pair_tree.query(shapely.linestrings(np.stack([p, p + r], axis=1))))
    inside = (t > 0) & (t < 1)
    walk, pair = moving[walk[inside]], pair[inside]
    return np.concatenate([walk, walk]), np.concatenate([lw.pairs[pair, 0], lw.pairs[pair, 1]])


def _ties(lw: Linework, p: np.ndarray, r: np.ndarray, walk: np.ndarray, pair: np.ndarray):
    """(segment index, t, pair index) where the two segments of the competing pair ``pair[h]`` are
    equally near p + t r (of segment ``walk[h]``)."""
    if not len(pair):
        return walk, np.zeros(0), pair
    tie_t, tie = _equal_distances(lw, p.take(walk, axis=0), r.take(walk, axis=0), pair)
    return walk[tie], tie_t, pair[tie]


def _segment_crossings(p, r, a, s) -> tuple[np.ndarray, np.ndarray]:
    """(hit index, t) where p + t r (t in [0, 1]) meets a + u s (u in [0, 1]); a collinear overlap
    gives the parameters of both ends of the stretch."""
    ap = a - p
    denom = _cross(r, s)
    safe = np.where(denom == 0, 1.0, denom)
    t, u = _cross(ap, s) / safe, _cross(ap, r) / safe
    hit = np.flatnonzero((denom != 0) & (u >= 0) & (u <= 1))
    collinear = np.flatnonzero((denom == 0) & (_cross(ap, r) == 0))
    rr = np.einsum("ij,ij->i", r, r)
    ends = [np.einsum("ij,ij->i", ap[collinear] + k * s[collinear], r[collinear]) / rr[collinear] for k in (0, 1)]
    return np.concatenate([hit, collinear, collinear]), np.concatenate([t[hit], *ends])


def _distance_pieces(polylines: Polylines, segment: np.ndarray, p, r) -> tuple[np.ndarray, np.ndarray]:
    """Squared distance from p + t r to each segment, as three quadratics in t (coefficients
    [piece, (t², t, 1)]: nearest to the start vertex, to the interior, to the end vertex), and
    the segment parameter of the foot of the perpendicular, (s0, s1) with s = s0 + s1 t."""
    a = polylines.start.take(segment, axis=0)
    w = polylines.end.take(segment, axis=0) - a
    pa = p - a
    pb = pa - w
    left, right = np.concatenate([w, r, pa, pa, pb, pb, pa, r]), np.concatenate([w, r, r, pa, r, pb, w, w])
    ll, rr, pa_r, pa_pa, pb_r, pb_pb, pa_w, r_w = (left[:, 0] * right[:, 0] + left[:, 1] * right[:, 1]).reshape(8, -1)
    cw, cr = _cross(np.concatenate([pa, r]), np.concatenate([w, w])).reshape(2, -1)
    quads = np.empty((len(a), 3, 3))
    quads[:, 0, 0] = quads[:, 2, 0] = rr
    quads[:, 0, 1], quads[:, 0, 2] = 2 * pa_r, pa_pa
    quads[:, 1, 0], quads[:, 1, 1], quads[:, 1, 2] = cr * cr / ll, 2 * cw * cr / ll, cw * cw / ll
    quads[:, 2, 1], quads[:, 2, 2] = 2 * pb_r, pb_pb
    return quads, np.stack([pa_w / ll, r_w / ll], 1)


def _equal_distances(lw: Linework, p, r, pair) -> tuple[np.ndarray, np.ndarray]:
    """(t, hit index) where the two segments of ``pair[h]`` are equally near p + t r, within their
    lane's reach, and no segment of their centreline is nearer (where the nearest segment may jump
    between them)."""
    n = len(pair)
    quads, foot = _distance_pieces(
        lw.polylines, lw.pairs.take(pair, axis=0).T.ravel(), np.tile(p, (2, 1)), np.tile(r, (2, 1))
    )
    met = _pieces_met(foot)
    combo = np.flatnonzero(met[:n, :, None] & met[n:, None, :])
    hit, piece_i, piece_j = combo // 9, combo // 3 % 3, combo % 3
    flat_quads = quads.reshape(-1, 3)
    difference = flat_quads.take(hit * 3 + piece_i, axis=0) - flat_quads.take((n + hit) * 3 + piece_j, axis=0)
    roots = _quadratic_roots(difference[:, 0], difference[:, 1], difference[:, 2])
    flat = np.flatnonzero((roots > 0) & (roots < 1))
    t = roots.reshape(-1)[flat]
    hit, piece_i, piece_j = hit[flat // 2], piece_i[flat // 2], piece_j[flat // 2]
    valid = _in_piece(foot.take(hit, axis=0), piece_i, t) & _in_piece(foot.take(n + hit, axis=0), piece_j, t)
    hit, piece_i, t = hit[valid], piece_i[valid], t[valid]
    quad = quads.reshape(-1, 3).take(hit * 3 + piece_i, axis=0)
    own = np.sqrt(np.maximum(quad[:, 0] * t * t + quad[:, 1] * t + quad[:, 2], 0.0))
    within = own <= lw.pair_reach[pair[hit]]
    hit, t, own = hit[within], t[within], own[within]
    points = shapely.points(p.take(hit, axis=0) + t[:, None] * r.take(hit, axis=0))
    nearest = shapely.distance(points, lw.polylines.geometries[lw.pair_lane[pair[hit]]])
    keep = own <= nearest + TIE_M
    return t[keep], hit[keep]


def _wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


def _pieces_met(s: np.ndarray) -> np.ndarray:
    """Per row of foot parameters (s0, s1), whether s0 + s1 t may lie in each distance piece's
    range for some t in [0, 1] (rows of 3 booleans; a superset of where :func:`_in_piece` holds, by
    a margin far above the rounding of s0 + s1 t; NaN rows meet every piece): only those pieces'
    pairs are solved."""
    s0, s1 = s[:, 0], s[:, 1]
    end = s0 + s1
    margin = 1e-12 * (np.abs(s0) + np.abs(s1))
    low, high = np.minimum(s0, end) - margin, np.maximum(s0, end) + margin
    met = np.empty((len(s), 3), dtype=bool)
    for piece, (piece_low, piece_high) in enumerate(PIECE_RANGE):
        met[:, piece] = ~((high < piece_low) | (low > piece_high))
    return met


def _in_piece(s: np.ndarray, piece: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Whether the foot parameter s0 + s1 t lies in the range of the distance piece (with slack)."""
    foot = s[:, 0] + s[:, 1] * t
    low, high = PIECE_RANGE.take(piece, axis=0).T
    return (foot >= low) & (foot <= high)


def _quadratic_roots(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """The real roots of a t² + b t + c (shape (..., 2); NaN where absent)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        size = np.abs(a)
        linear = size <= 1e-12 * (size + np.abs(b) + np.abs(c))
        disc = b * b - 4 * a * c
        q = -(b + np.copysign(np.sqrt(np.where(disc >= 0, disc, np.nan)), b)) / 2
        first = np.where(linear, -c / b, q / a)
        second = np.where(linear, np.nan, c / q)
    return np.stack([first, second], -1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


@dataclass
class _Branches(_Columns):
    """Walks under enumeration: start row, D interval, step count, and the end so far (X + D a)."""

    row: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    steps: np.ndarray
    ax: np.ndarray
    ay: np.ndarray


def follow_pieces(
    geometry: MapGeometry,
    field: Field,
    x: np.ndarray,
    y: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    target: np.ndarray | None = None,
) -> Pieces:
    """The pieces of the walks from (x[i], y[i]) for every D in [lo[i], hi[i]] (metres, finite,
    lo <= hi, hi <= STEP_M * MAX_STEPS); see the module docstring. With ``target`` (rows of
    x_lo, x_hi, y_lo, y_hi per start), only the pieces whose end may lie in that box: a walk
    whose remaining steps cannot bring it there is dropped as soon as that is certain."""
    lw = linework(geometry)
    b = _by_step_count(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float))
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    for k in range(int(b.steps.max(initial=0))):
        if target is not None:
            b = b.take(np.flatnonzero(_may_reach(x, y, b, b.steps - k, target)))
        walking = k < b.steps
        moved = _step(geometry, field, lw, x, y, b.take(np.flatnonzero(walking)))
        b = _concat(b.take(np.flatnonzero(~walking)), moved)
    if target is not None:
        b = b.take(np.flatnonzero(_may_reach(x, y, b, np.zeros(len(b.row)), target)))
    return _ends(geometry, field, lw, x, y, b)


def _may_reach(x, y, b: _Branches, left: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Whether each branch's walk may still end in its start's target box: its current points span
    a box, and the ``left`` steps move at most ``left * |D| / steps`` metres."""
    px, qx = x[b.row] + b.lo * b.ax, x[b.row] + b.hi * b.ax
    py, qy = y[b.row] + b.lo * b.ay, y[b.row] + b.hi * b.ay
    reach = np.maximum(left, 0) * np.maximum(np.abs(b.lo), np.abs(b.hi)) / b.steps + TIE_M
    box = target[b.row]
    return (
        (np.minimum(px, qx) - reach <= box[:, 1])
        & (np.maximum(px, qx) + reach >= box[:, 0])
        & (np.minimum(py, qy) - reach <= box[:, 3])
        & (np.maximum(py, qy) + reach >= box[:, 2])
    )


def _by_step_count(lo: np.ndarray, hi: np.ndarray) -> _Branches:
    """One branch per start and step count its D interval allows (n = 4 up to 20 m, then
    (5 (n - 1), 5 n] for n)."""
    first, last = steps_for(lo), steps_for(hi)
    counts = last - first + 1
    row = np.repeat(np.arange(len(lo)), counts)
    steps = np.repeat(first, counts) + (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
    low = np.maximum(lo[row], np.where(steps > MIN_STEPS, STEP_M * (steps - 1), -np.inf))
    high = np.minimum(hi[row], STEP_M * steps.astype(float))
    zeros = np.zeros(len(row))
    return _Branches(row, low, high, steps, zeros, zeros.copy())


def _split(lw: Linework, x, y, b: _Branches, only=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cut each branch's D interval where its current point crosses the linework:
    (branch index, lo, hi) of the sub-intervals, in branch then D order (``only`` as in
    :func:`crossings`)."""
    px, py = x[b.row] + b.lo * b.ax, y[b.row] + b.lo * b.ay
    qx, qy = x[b.row] + b.hi * b.ax, y[b.row] + b.hi * b.ay
    walk, t = crossings(lw, px, py, qx, qy, only)
    n = len(b.row)
    owner = np.concatenate([np.arange(n), np.arange(n), walk])
    cut = np.concatenate([np.zeros(n), np.ones(n), t])
    order = np.lexsort((cut, owner))
    owner, cut = owner[order], cut[order]
    pair = (owner[:-1] == owner[1:]) & (cut[1:] > cut[:-1])
    branch = owner[:-1][pair]
    width = b.hi[branch] - b.lo[branch]
    low = b.lo[branch] + cut[:-1][pair] * width
    high = np.where(cut[1:][pair] == 1, b.hi[branch], b.lo[branch] + cut[1:][pair] * width)
    return branch, low, high


def _step(geometry: MapGeometry, field: Field, lw: Linework, x, y, b: _Branches) -> _Branches:
    """Every branch takes its next step: split where the heading may change, then move."""
    branch, low, high = _split(lw, x, y, b)
    mid = (low + high) / 2
    heading = geometry.scenic_headings(
        field, x[b.row[branch]] + mid * b.ax[branch], y[b.row[branch]] + mid * b.ay[branch], _no_terms
    )
    branch, low, high, heading = _merge(branch, low, high, heading)
    moved = b.take(branch)
    moved.lo, moved.hi = low, high
    moved.ax = moved.ax - np.sin(heading) / moved.steps
    moved.ay = moved.ay + np.cos(heading) / moved.steps
    return moved


def _merge(branch, low, high, heading):
    """Join neighbouring sub-intervals of one branch that take the same heading."""
    order = np.lexsort((low, branch))
    branch, low, high, heading = branch[order], low[order], high[order], heading[order]
    new = np.ones(len(branch), dtype=bool)
    new[1:] = (branch[1:] != branch[:-1]) | (heading[1:] != heading[:-1])
    starts = np.flatnonzero(new)
    ends = np.append(starts[1:], len(branch))[: len(starts)] - 1
    return branch[starts], low[starts], high[ends], heading[starts]


def _ends(geometry: MapGeometry, field: Field, lw: Linework, x, y, b: _Branches) -> Pieces:
    """The pieces: each branch cut where the end's field values may change, one per value."""
    branch, low, high = _split(lw, x, y, b)
    mid = (low + high) / 2
    ex, ey = x[b.row[branch]] + mid * b.ax[branch], y[b.row[branch]] + mid * b.ay[branch]
    rows, headings = geometry.field_values(field, ex, ey, _no_terms)
    piece = branch[rows]
    return Pieces(b.row[piece], low[rows], high[rows], b.ax[piece], b.ay[piece], headings)


def _concat(a: _Branches, b: _Branches) -> _Branches:
    return _Branches(
        *(np.concatenate([getattr(a, k), getattr(b, k)]) for k in ("row", "lo", "hi", "steps", "ax", "ay"))
    )


def _no_terms(term):
    raise ValueError(f"roadDirection has no parameters, got {term!r}")


_LINEWORK: weakref.WeakKeyDictionary[MapGeometry, Linework] = weakref.WeakKeyDictionary()
