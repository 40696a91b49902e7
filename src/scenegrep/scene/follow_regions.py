"""Every walk ``follow roadDirection from X for D`` can take when the start X runs along a segment
and the distance D over an interval: regions of (s, D) on which the sequence of headings is one.

The start is ``X = A + s e`` (``s`` metres from the segment's first point A along its unit
direction e, 0 <= s <= L) and D is in metres. Scenic's walk (:mod:`.follow`) takes
``n = max(4, ceil(D / 5))`` steps of ``D / n`` metres; with the headings h_0 .. h_{k-1} of the
steps taken so far its k-th point is ``p_k = A + s e + D c_k``, ``c_k = (1/n) sum_{j<k} u(h_j)``,
``u(h) = (-sin h, cos h)`` (radians, 0 = +y): affine in (s, D).

The heading at a point changes only across the linework of :mod:`.follow_pieces` (or along a
curve where two segments of a folded centreline are equally near: see below). The preimage of a
linework segment under the affine map (s, D) -> p_k is a segment of the (s, D) plane (a line
across it where the map is not one-to-one), so cutting a region of (s, D) by those preimages
gives faces on which h_k is one constant, read at an interior point with
:meth:`~.geometry.MapGeometry.scenic_headings`. Faces with the same h_k are joined: a region is a
(not necessarily convex) polygon of (s, D) with one heading sequence. The step counts split D's
interval first (and its sign: ``|D|`` is linear on each part).

A region is clipped, before each step k, to the (s, D) whose point can still reach the target box:
the remaining ``n - k`` steps move at most ``(n - k) |D| / n`` metres, so the point's projection
on each of four directions (the axes and diagonals) lies within that of the box's. After the
last step the end is clipped to the box itself and cut once more, reading every value the field
has at the end (:meth:`~.geometry.MapGeometry.field_values`); the result is exact: the final
regions are every (s, D) whose walk ends in the box, grouped by heading sequence and end value.

Where two competing segments of a folded centreline become equally near along a face's edges
(the heading may change along a curve through the face, not at the straight linework) the face
takes each of their headings as well as the one read inside: the regions then cover every walk
but may hold (s, D) that walk otherwise, so the solver walks its witnesses again. Where the
nearest lane counts (in an intersection area between its lanes, within 5 cm of a lane) it is
read at the face's interior point, the assumption :mod:`.follow_pieces` makes per piece.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import shapely

from .follow import MIN_STEPS, STEP_M
from .follow_pieces import Linework, linework, ties
from .geometry import MapGeometry
from .regions import Field

TIE_M = 1e-9
"""Slack on the reach and box constraints (metres)."""

DIRECTIONS = np.array([[1.0, 0.0], [0.0, 1.0], [np.sqrt(0.5), np.sqrt(0.5)], [np.sqrt(0.5), -np.sqrt(0.5)]])
"""Unit directions whose projections bound where a walk point can still reach the target box."""


@dataclass
class StartRegion:
    """(s, D) values of one start segment for which the walk takes ``steps`` steps with one heading
    sequence and ends at ``A + s e + D slope`` where the field takes ``heading`` (metres, radians;
    ``shape`` a shapely polygon of (s, D))."""

    segment: int
    steps: int
    slope: np.ndarray
    heading: float
    shape: shapely.Geometry


@dataclass(frozen=True)
class _Start:
    """One start segment: first point A, unit direction e (metres)."""

    a: np.ndarray
    e: np.ndarray


def start_regions(
    geometry: MapGeometry,
    field: Field,
    start: np.ndarray,
    end: np.ndarray,
    lo: float,
    hi: float,
    target: tuple[float, float, float, float],
    hints: np.ndarray | None = None,
) -> Iterator[StartRegion]:
    """The final regions (see the module docstring) of the walks from every point of the segments
    ``start[i]``-``end[i]`` (rows of x, y) for every D in [lo, hi] (metres, lo < hi) that end in the
    box ``target`` (x_lo, x_hi, y_lo, y_hi), segment after segment in the given order, each
    region as soon as it is found. Within a segment the branches go depth first, the one nearest
    to its hint (a row of s, D: where a match is likely) first."""
    lw = linework(geometry)
    box = np.array([[target[0], target[2]], [target[1], target[2]], [target[0], target[3]], [target[1], target[3]]])
    project = box @ DIRECTIONS.T
    window = (project.min(axis=0), project.max(axis=0))
    for index in range(len(start)):
        delta = np.asarray(end[index], dtype=float) - start[index]
        length = float(np.hypot(*delta))
        if length == 0:
            continue
        seg = _Start(np.asarray(start[index], dtype=float), delta / length)
        hint = shapely.Point(hints[index]) if hints is not None else None
        parts = [(shapely.box(0.0, d0, length, d1), np.zeros(2), 0, steps) for steps, d0, d1 in _distance_parts(lo, hi)]
        stack = _nearest_last(parts, hint)
        while stack:
            shape, c, k, steps = stack.pop()
            sign = 1.0 if shape.bounds[1] >= 0 else -1.0
            shape = _clip(shape, *_reach(seg, c, sign * (steps - k) / steps, window))
            faces = _faces(lw, geometry, field, seg, c, shape, last=k == steps)
            if k == steps:
                yield from (StartRegion(index, steps, c, heading, part) for part, heading in faces)
                continue
            moved = [(part, c + np.array([-np.sin(h), np.cos(h)]) / steps, k + 1, steps) for part, h in faces]
            stack.extend(_nearest_last(moved, hint))


def _nearest_last(branches: list, hint: shapely.Point | None) -> list:
    """The branches ordered so that the one nearest to the hint comes last (popped first)."""
    if hint is None or len(branches) < 2:
        return branches
    distance = shapely.distance(np.array([b[0] for b in branches], dtype=object), hint)
    return [branches[i] for i in np.argsort(-distance, kind="stable")]


def _distance_parts(lo: float, hi: float) -> list[tuple[int, float, float]]:
    """(step count, D low, D high) parts of [lo, hi]: a step count is constant on each (4 up to
    20 m, then n on (5 (n - 1), 5 n]), and so is the sign of D."""
    cuts = [lo, hi] + [c for c in (0.0,) if lo < c < hi]
    top = int(np.ceil(hi / STEP_M))
    cuts += [STEP_M * n for n in range(MIN_STEPS, top) if lo < STEP_M * n < hi]
    cuts = sorted(set(cuts))
    parts = []
    for d0, d1 in zip(cuts[:-1], cuts[1:]):
        steps = max(MIN_STEPS, int(np.ceil(((d0 + d1) / 2) / STEP_M)))
        parts.append((steps, d0, d1))
    return parts


def _reach(seg: _Start, c: np.ndarray, slack: float, window) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Half-planes ``alpha s + beta D <= gamma`` keeping ``v . p`` within ``slack * D`` (``slack`` is
    the signed fraction of |D| still to walk) of the box's projection, for each direction v."""
    low, high = window
    ve, vc, va = DIRECTIONS @ seg.e, DIRECTIONS @ c, DIRECTIONS @ seg.a
    alpha = np.concatenate([ve, -ve])
    beta = np.concatenate([vc - slack, -vc - slack])
    gamma = np.concatenate([high - va, va - low]) + TIE_M
    return alpha, beta, gamma


def _clip(shape: shapely.Geometry, alpha: np.ndarray, beta: np.ndarray, gamma: np.ndarray) -> shapely.Geometry:
    """The part of a polygon of (s, D) where every ``alpha s + beta D <= gamma`` holds (its
    polygonal part: a piece of no area is dropped)."""
    if shape.is_empty:
        return shape
    s0, d0, s1, d1 = shape.bounds
    ring = np.array([[s0 - 1, d0 - 1], [s1 + 1, d0 - 1], [s1 + 1, d1 + 1], [s0 - 1, d1 + 1]])
    for a, b, g in zip(alpha.tolist(), beta.tolist(), gamma.tolist()):
        ring = _cut(ring, a, b, g)
        if len(ring) < 3:
            return shapely.Polygon()
    clipped = shapely.intersection(shape, shapely.Polygon(ring))
    parts = [p for p in shapely.get_parts(clipped) if isinstance(p, shapely.Polygon) and p.area > 0]
    return shapely.MultiPolygon(parts) if len(parts) > 1 else (parts[0] if parts else shapely.Polygon())


def _cut(ring: np.ndarray, a: float, b: float, g: float) -> np.ndarray:
    """A convex polygon (vertex rows) cut to ``a s + b D <= g`` (Sutherland-Hodgman)."""
    value = ring @ np.array([a, b]) - g
    kept = []
    for i in range(len(ring)):
        j = (i + 1) % len(ring)
        if value[i] <= 0:
            kept.append(ring[i])
        if (value[i] < 0 < value[j]) or (value[j] < 0 < value[i]):
            t = value[i] / (value[i] - value[j])
            kept.append(ring[i] + t * (ring[j] - ring[i]))
    return np.array(kept).reshape(-1, 2)


def _image(seg: _Start, c: np.ndarray, points: np.ndarray) -> np.ndarray:
    """The walk points p = A + s e + D c of (s, D) rows."""
    return seg.a + points[:, :1] * seg.e + points[:, 1:2] * c


def _faces(lw: Linework, geometry: MapGeometry, field: Field, seg: _Start, c: np.ndarray, shape, last: bool):
    """(part of the region, heading) pairs: the region cut where the walk point crosses the
    linework, faces joined by heading (Scenic's step heading, or with ``last`` every value of the
    field at the end)."""
    if shape.is_empty:
        return []
    faces = _cut_by_linework(lw, seg, c, shape)
    inside = shapely.point_on_surface(faces)
    xy = _image(seg, c, shapely.get_coordinates(inside))
    if last:
        rows, headings = geometry.field_values(field, xy[:, 0], xy[:, 1], _no_terms)
    else:
        rows, headings = np.arange(len(faces)), geometry.scenic_headings(field, xy[:, 0], xy[:, 1], _no_terms)
    tie_rows, tie_headings = _tie_headings(lw, seg, c, faces)
    rows, headings = np.concatenate([rows, tie_rows]), np.concatenate([headings, tie_headings])
    pairs = np.unique(np.stack([rows, headings], axis=1), axis=0)
    rows, headings = pairs[:, 0].astype(np.intp), pairs[:, 1]
    found = []
    for heading in np.unique(headings).tolist():
        parts = faces[rows[headings == heading]]
        found.append((parts[0] if len(parts) == 1 else shapely.union_all(parts), heading))
    return found


def _cut_by_linework(lw: Linework, seg: _Start, c: np.ndarray, shape: shapely.Geometry) -> np.ndarray:
    """The faces of the region cut by the preimages of the linework segments its image meets."""
    s0, d0, s1, d1 = shape.bounds
    corners = _image(seg, c, np.array([[s0, d0], [s1, d0], [s0, d1], [s1, d1]]))
    near = lw.tree.query(shapely.box(*corners.min(axis=0), *corners.max(axis=0)))
    lines = _preimages(lw.start[near], lw.end[near], seg, c, (s0 - 1, d0 - 1, s1 + 1, d1 + 1))
    lines = lines[shapely.intersects(shape, lines)]
    if not len(lines):
        return shapely.get_parts(shape)
    noded = shapely.union_all(np.append(lines, shapely.boundary(shape)))
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    faces = faces[shapely.area(faces) > 0]
    return faces[shapely.contains(shape, shapely.point_on_surface(faces))]


def _preimages(p: np.ndarray, q: np.ndarray, seg: _Start, c: np.ndarray, bounds) -> np.ndarray:
    """The (s, D) points mapped onto each segment p_i-q_i, as line strings within ``bounds``
    (s0, d0, s1, d1); a segment parallel to every image point's motion gives none."""
    w = q - p
    normal = np.stack([-w[:, 1], w[:, 0]], axis=1)
    alpha, beta = normal @ seg.e, normal @ c
    gamma = np.einsum("ij,ij->i", normal, p - seg.a)
    s0, d0, s1, d1 = bounds
    by_d = np.abs(alpha) >= np.abs(beta)
    keep = np.maximum(np.abs(alpha), np.abs(beta)) > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        # the line as (s, D) = origin + lam * step, lam in [0, 1], across the bounds
        origin = np.where(
            by_d[:, None],
            np.stack([(gamma - beta * d0) / alpha, np.full_like(alpha, d0)], 1),
            np.stack([np.full_like(alpha, s0), (gamma - alpha * s0) / beta], 1),
        )
        far = np.where(
            by_d[:, None],
            np.stack([(gamma - beta * d1) / alpha, np.full_like(alpha, d1)], 1),
            np.stack([np.full_like(alpha, s1), (gamma - alpha * s1) / beta], 1),
        )
    step = far - origin
    low, high = np.zeros(len(p)), np.ones(len(p))
    ww = np.einsum("ij,ij->i", w, w)
    foot0 = np.einsum("ij,ij->i", _image(seg, c, origin) - p, w) / np.where(ww > 0, ww, 1.0)
    foot1 = (step[:, 0] * (seg.e @ w.T) + step[:, 1] * (c @ w.T)) / np.where(ww > 0, ww, 1.0)
    for f0, f1, lo, hi in (
        (origin[:, 0], step[:, 0], s0, s1),
        (origin[:, 1], step[:, 1], d0, d1),
        (foot0, foot1, 0.0, 1.0),
    ):
        low, high = _limit(low, high, f0, f1, lo, hi)
    keep &= (low < high) & (ww > 0)
    a, b = origin[keep] + low[keep, None] * step[keep], origin[keep] + high[keep, None] * step[keep]
    return shapely.linestrings(np.stack([a, b], axis=1))


def _limit(low, high, f0, f1, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """Narrow [low, high] to the lam where lo <= f0 + f1 lam <= hi."""
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (lo - f0) / f1, (hi - f0) / f1
    flat = f1 == 0
    inside = (f0 >= lo) & (f0 <= hi)
    new_low = np.where(flat, np.where(inside, low, np.inf), np.maximum(low, np.minimum(a, b)))
    new_high = np.where(flat, np.where(inside, high, -np.inf), np.minimum(high, np.maximum(a, b)))
    return new_low, new_high


def _tie_headings(lw: Linework, seg: _Start, c: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(face index, heading) pairs: where two competing centreline segments become equally near
    along an edge of a face's image, the headings of both (the heading may change along a curve
    through the face, so the face may take either). Only faces whose image comes where a lane's
    direction may count are checked."""
    hulls = shapely.convex_hull(
        shapely.multipoints(_image(seg, c, shapely.get_coordinates(faces)), indices=_owners(faces))
    )
    on_lanes = np.unique(lw.lane_reach.query(hulls, predicate="intersects")[0])
    if not len(on_lanes):
        return np.zeros(0, dtype=np.intp), np.zeros(0)
    coords, owner = shapely.get_coordinates(shapely.get_rings(faces), return_index=True)
    ring_face = np.repeat(np.arange(len(faces)), shapely.get_num_interior_rings(faces) + 1)
    same = (owner[1:] == owner[:-1]) & np.isin(ring_face[owner[:-1]], on_lanes)
    edges = np.concatenate([coords[:-1][same], coords[1:][same]], axis=1)
    face = ring_face[owner[:-1][same]]
    # an edge two faces share is checked once (either direction)
    key = np.where((edges[:, :2] <= edges[:, 2:]).all(axis=1, keepdims=True), edges, edges[:, [2, 3, 0, 1]])
    unique, back = np.unique(key, axis=0, return_inverse=True)
    edge, segment = ties(lw, _image(seg, c, unique[:, :2]), _image(seg, c, unique[:, 2:]))
    hit = np.isin(back.ravel(), edge)
    if not hit.any():
        return face[:0], np.zeros(0)
    which = {e: segment[edge == e] for e in np.unique(edge).tolist()}
    rows = [(f, h) for f, e in zip(face[hit].tolist(), back.ravel()[hit].tolist()) for h in which[e].tolist()]
    return np.array([r[0] for r in rows], dtype=np.intp), lw.polylines.heading[np.array([r[1] for r in rows])]


def _owners(geometries: np.ndarray) -> np.ndarray:
    """For each coordinate of the geometries (shapely's order), the index of its geometry."""
    return np.repeat(np.arange(len(geometries)), shapely.get_num_coordinates(geometries))


def _no_terms(term):
    raise ValueError(f"roadDirection has no parameters, got {term!r}")
