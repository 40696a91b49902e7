"""Exact 2-D shape tests on arrays: oriented boxes and circular sectors.

Boxes are (x, y, heading, length, width): centre (m), Scenic heading (rad),
length along the heading, width across it. A sector is (cx, cy, radius,
heading, angle): centre, radius (m), axis heading and opening angle (rad); an
angle of 2π or more is the whole disc. Every function takes arrays of equal
length (or scalars) and answers element-wise.
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import box_corners, heading_of_vector, normalize_angle

_EPS = 1e-12


def points_in_sector(px, py, cx, cy, radius, heading, angle) -> np.ndarray:
    """Whether each point lies in its sector (boundary included)."""
    dx, dy = np.asarray(px) - cx, np.asarray(py) - cy
    dist = np.hypot(dx, dy)
    bearing = np.abs(normalize_angle(heading_of_vector(dx, dy) - heading))
    within = (angle >= 2 * np.pi) | (bearing <= np.asarray(angle) / 2) | (dist <= _EPS)
    return (dist <= radius) & within


def points_near_sector(px, py, cx, cy, radius, heading, angle, reach) -> np.ndarray:
    """Whether some point within ``reach`` (m, Euclidean) of each point may lie in its sector.

    Sound (never False when such a point exists) and exact when reach is 0: the test widens
    the radius by ``reach`` and the half-angle by the angle ``reach`` subtends.
    """
    dx, dy = np.asarray(px) - cx, np.asarray(py) - cy
    dist = np.hypot(dx, dy)
    bearing = np.abs(normalize_angle(heading_of_vector(dx, dy) - heading))
    slack = np.arcsin(np.clip(np.divide(reach, dist, out=np.ones_like(dist), where=dist > 0), 0, 1))
    within = (angle >= 2 * np.pi) | (bearing <= np.asarray(angle) / 2 + slack) | (dist <= reach + _EPS)
    return (dist <= np.asarray(radius) + reach) & within


def points_in_boxes(px, py, x, y, heading, length, width) -> np.ndarray:
    """Whether each point lies in its oriented box (boundary included)."""
    dx, dy = np.asarray(px) - x, np.asarray(py) - y
    forward = -dx * np.sin(heading) + dy * np.cos(heading)
    across = dx * np.cos(heading) + dy * np.sin(heading)
    return (np.abs(forward) <= np.asarray(length) / 2 + _EPS) & (np.abs(across) <= np.asarray(width) / 2 + _EPS)


def _segments_cross(a0, a1, b0, b1) -> np.ndarray:
    """Whether segments a0-a1 and b0-b1 (arrays of shape (n, 2)) meet (touching counts)."""

    def orient(p, q, r):
        return (q[:, 0] - p[:, 0]) * (r[:, 1] - p[:, 1]) - (q[:, 1] - p[:, 1]) * (r[:, 0] - p[:, 0])

    o1, o2, o3, o4 = orient(a0, a1, b0), orient(a0, a1, b1), orient(b0, b1, a0), orient(b0, b1, a1)
    proper = (o1 * o2 <= 0) & (o3 * o4 <= 0)
    collinear = (np.abs(o1) <= _EPS) & (np.abs(o2) <= _EPS)
    overlap = (
        (np.minimum(a0[:, 0], a1[:, 0]) <= np.maximum(b0[:, 0], b1[:, 0]) + _EPS)
        & (np.minimum(b0[:, 0], b1[:, 0]) <= np.maximum(a0[:, 0], a1[:, 0]) + _EPS)
        & (np.minimum(a0[:, 1], a1[:, 1]) <= np.maximum(b0[:, 1], b1[:, 1]) + _EPS)
        & (np.minimum(b0[:, 1], b1[:, 1]) <= np.maximum(a0[:, 1], a1[:, 1]) + _EPS)
    )
    return proper & (~collinear | overlap)


def _segment_meets_arc(p0, p1, c, radius, heading, angle) -> np.ndarray:
    """Whether segment p0-p1 crosses the circle of radius ``radius`` about c inside the sector's angle."""
    d = p1 - p0
    f = p0 - c
    a = np.einsum("ij,ij->i", d, d)
    b = 2 * np.einsum("ij,ij->i", f, d)
    cc = np.einsum("ij,ij->i", f, f) - radius**2
    disc = b * b - 4 * a * cc
    hit = np.zeros(len(a), dtype=bool)
    ok = (disc >= 0) & (a > 0)
    root = np.sqrt(np.where(ok, disc, 0))
    for sign in (-1, 1):
        t = np.divide(-b + sign * root, 2 * a, out=np.full_like(a, -1.0), where=ok)
        inside = ok & (t >= -_EPS) & (t <= 1 + _EPS)
        q = p0 + d * t[:, None]
        bearing = np.abs(normalize_angle(heading_of_vector(q[:, 0] - c[:, 0], q[:, 1] - c[:, 1]) - heading))
        hit |= inside & ((angle >= 2 * np.pi) | (bearing <= angle / 2 + 1e-12))
    return hit


def boxes_meet_sectors(x, y, heading, length, width, cx, cy, radius, sector_heading, angle) -> np.ndarray:
    """Whether each oriented box intersects its sector (touching counts): exact up to rounding."""
    x, y, heading, length, width, cx, cy, radius, sector_heading, angle = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(v, dtype=np.float64))
            for v in (x, y, heading, length, width, cx, cy, radius, sector_heading, angle)
        )
    )
    corners = box_corners(x, y, heading, length, width)
    hit = points_in_boxes(cx, cy, x, y, heading, length, width)
    for k in range(4):
        hit |= points_in_sector(corners[:, k, 0], corners[:, k, 1], cx, cy, radius, sector_heading, angle)
    centre = np.stack([cx, cy], axis=1)
    partial = angle < 2 * np.pi
    rays = [
        centre
        + radius[:, None]
        * np.stack([-np.sin(sector_heading + s * angle / 2), np.cos(sector_heading + s * angle / 2)], axis=1)
        for s in (-1, 1)
    ]
    for k in range(4):
        p0, p1 = corners[:, k], corners[:, (k + 1) % 4]
        hit |= _segment_meets_arc(p0, p1, centre, radius, sector_heading, angle)
        for ray in rays:
            hit |= partial & _segments_cross(p0, p1, centre, ray)
    return hit


def boxes_in_sectors(x, y, heading, length, width, cx, cy, radius, sector_heading, angle) -> np.ndarray:
    """Whether each oriented box lies inside its sector: its corners are inside, and (for sectors
    wider than a half-disc, which are not convex) no box edge crosses the sector's straight sides."""
    corners = box_corners(x, y, heading, length, width)
    inside = np.ones(len(corners), dtype=bool)
    for k in range(4):
        inside &= points_in_sector(corners[:, k, 0], corners[:, k, 1], cx, cy, radius, sector_heading, angle)
    reflex = (np.asarray(angle) > np.pi) & (np.asarray(angle) < 2 * np.pi)
    if np.any(reflex & inside):
        centre = np.stack(np.broadcast_arrays(cx, cy), axis=1).astype(float)
        for s in (-1, 1):
            direction = np.asarray(sector_heading) + s * np.asarray(angle) / 2
            ray = centre + np.asarray(radius)[..., None] * np.stack([-np.sin(direction), np.cos(direction)], axis=-1)
            for k in range(4):
                crossing = _segments_cross(corners[:, k], corners[:, (k + 1) % 4], centre, ray)
                inside &= ~(reflex & crossing & ~points_in_boxes(cx, cy, x, y, heading, length, width))
    return inside


def boxes_overlap(a: tuple, b: tuple) -> np.ndarray:
    """Whether oriented boxes a[i] and b[i] intersect (touching counts), by separating axes: the
    two boxes' own axes (unit vectors along and across their headings, so degenerate boxes of
    zero size are points or segments, not special cases)."""
    ca, cb = box_corners(*a), box_corners(*b)
    separated = np.zeros(len(ca), dtype=bool)
    for heading in (np.atleast_1d(np.asarray(a[2], dtype=float)), np.atleast_1d(np.asarray(b[2], dtype=float))):
        for axis in (
            np.stack([-np.sin(heading), np.cos(heading)], axis=1),
            np.stack([np.cos(heading), np.sin(heading)], axis=1),
        ):
            pa = np.einsum("ikj,ij->ik", ca, np.broadcast_to(axis, (len(ca), 2)))
            pb = np.einsum("ikj,ij->ik", cb, np.broadcast_to(axis, (len(cb), 2)))
            separated |= (pa.max(axis=1) < pb.min(axis=1) - _EPS) | (pb.max(axis=1) < pa.min(axis=1) - _EPS)
    return ~separated
