"""Lane shapes: from centrelines and widths (maps that give lanes as centrelines), and from
left and right bounds (maps that give lanes as bounds running in the direction of travel)."""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike
from shapely.geometry.base import BaseGeometry


def resample_polyline(line: np.ndarray, n: int) -> np.ndarray:
    """``n`` points (n x 2) evenly spaced by arc length along a polyline (k x 2)."""
    geom = shapely.linestrings(line)
    return shapely.get_coordinates(shapely.line_interpolate_point(geom, np.linspace(0.0, 1.0, n), normalized=True))


BOUND_CENTRELINE_POINTS = 20
"""How many points a centreline derived from a lane's two bounds has."""


def centreline_between(left: np.ndarray, right: np.ndarray, n: int = BOUND_CENTRELINE_POINTS) -> np.ndarray:
    """The centreline (n x 2) of a lane between its ``left`` and ``right`` bounds (k x 2, both in
    the direction of travel): the mean of the two bounds resampled to ``n`` points each."""
    return (resample_polyline(left, n) + resample_polyline(right, n)) / 2.0


def polygon_between(left: np.ndarray, right: np.ndarray) -> BaseGeometry:
    """The polygon of a lane between its ``left`` and ``right`` bounds (k x 2, in the direction
    of travel): the ring along the left bound and back along the right, made valid."""
    return shapely.make_valid(shapely.Polygon(np.vstack([left[:, :2], right[::-1, :2]])))


def left_normals(centreline: np.ndarray) -> np.ndarray:
    """Unit vectors pointing left of the direction of travel at each centreline point."""
    tangent = np.gradient(centreline, axis=0) if len(centreline) > 1 else np.array([[0.0, 1.0]])
    norm = np.linalg.norm(tangent, axis=1, keepdims=True)
    tangent = np.divide(tangent, norm, out=np.zeros_like(tangent), where=norm > 0)
    return np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)


def lane_polygon(centreline: np.ndarray, left_width: ArrayLike, right_width: ArrayLike) -> BaseGeometry:
    """The polygon between the centreline offset ``left_width`` metres to its left and
    ``right_width`` metres to its right (scalars or one value per centreline point)."""
    centre = np.asarray(centreline, dtype=np.float64)[:, :2]
    left = np.broadcast_to(np.asarray(left_width, dtype=np.float64), len(centre))[:, None]
    right = np.broadcast_to(np.asarray(right_width, dtype=np.float64), len(centre))[:, None]
    normals = left_normals(centre)
    ring = np.vstack([centre + normals * left, (centre - normals * right)[::-1]])
    return shapely.make_valid(shapely.Polygon(ring))


def line_strings(lines: list[np.ndarray]) -> np.ndarray:
    """An array of shapely LineStrings from polylines (k_i x 2 arrays) of different lengths."""
    if not lines:
        return np.array([], dtype=object)
    coords = np.concatenate([np.asarray(line, dtype=np.float64)[:, :2] for line in lines])
    indices = np.repeat(np.arange(len(lines)), [len(line) for line in lines])
    return shapely.linestrings(coords, indices=indices)
