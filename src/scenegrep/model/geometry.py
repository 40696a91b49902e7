"""Angle and frame conventions of the data model.

Positions are metres in the map frame (x east, y north). Headings are radians in
Scenic's convention: 0 points to +y (north), counter-clockwise positive,
normalised to (-pi, pi]. Most datasets give a *yaw* measured from +x; readers
convert with :func:`heading_from_yaw`. All functions accept scalars or arrays.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

TWO_PI = 2.0 * np.pi


def normalize_angle(angle: ArrayLike) -> np.ndarray:
    """Map radians into (-pi, pi]."""
    a = np.asarray(angle, dtype=np.float64)
    return np.pi - np.mod(np.pi - a, TWO_PI)


def heading_from_yaw(yaw: ArrayLike) -> np.ndarray:
    """Scenic heading (0 = +y, CCW) from a yaw measured CCW from +x (radians)."""
    return normalize_angle(np.asarray(yaw, dtype=np.float64) - np.pi / 2)


def heading_from_atan2(yaw: np.ndarray) -> np.ndarray:
    """:func:`heading_from_yaw` of a float64 array of yaws in [-pi, pi] (atan2's range) or NaN,
    the same values bit for bit, written over ``yaw`` and returned, without ``np.mod`` (several
    times slower): there pi - (yaw - pi/2) lies in [pi/2, 5 pi/2], where its remainder by 2 pi
    is itself below 2 pi and one exact subtraction of 2 pi from 2 pi on."""
    np.subtract(yaw, np.pi / 2, out=yaw)
    np.subtract(np.pi, yaw, out=yaw)
    np.subtract(yaw, TWO_PI, out=yaw, where=yaw >= TWO_PI)
    return np.subtract(np.pi, yaw, out=yaw)


def yaw_from_heading(heading: ArrayLike) -> np.ndarray:
    """Yaw measured CCW from +x from a Scenic heading (radians), in (-pi, pi]."""
    return normalize_angle(np.asarray(heading, dtype=np.float64) + np.pi / 2)


def heading_of_vector(dx: ArrayLike, dy: ArrayLike) -> np.ndarray:
    """Scenic heading of the direction (dx, dy), in (-pi, pi]; e.g. (3, 4) gives -0.6435 rad."""
    return normalize_angle(np.arctan2(-np.asarray(dx, dtype=np.float64), np.asarray(dy, dtype=np.float64)))


def heading_difference(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Signed smallest rotation from heading b to heading a, in (-pi, pi]."""
    return normalize_angle(np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64))


def yaw_from_quaternion(qw: ArrayLike, qx: ArrayLike, qy: ArrayLike, qz: ArrayLike) -> np.ndarray:
    """Rotation about +z (yaw from +x, CCW, radians) of unit quaternions (w, x, y, z)."""
    qw, qx, qy, qz = (np.asarray(q, dtype=np.float64) for q in (qw, qx, qy, qz))
    return np.arctan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def rotation_matrices(qw: ArrayLike, qx: ArrayLike, qy: ArrayLike, qz: ArrayLike) -> np.ndarray:
    """3x3 rotation matrices, shape (n, 3, 3), of unit quaternions (w, x, y, z)."""
    w, x, y, z = (np.atleast_1d(np.asarray(q, dtype=np.float64)) for q in (qw, qx, qy, qz))
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=-1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=-1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=-2,
    )


def box_corners(x: ArrayLike, y: ArrayLike, heading: ArrayLike, length: ArrayLike, width: ArrayLike) -> np.ndarray:
    """Corners of top-down oriented boxes, shape (n, 4, 2), counter-clockwise from front-left.

    ``length`` runs along the heading direction, ``width`` across it.
    """
    x, y, h, length, width = (np.atleast_1d(np.asarray(v, dtype=np.float64)) for v in (x, y, heading, length, width))
    forward = np.stack([-np.sin(h), np.cos(h)], axis=-1)
    left = np.stack([-np.cos(h), -np.sin(h)], axis=-1)
    centre = np.stack([x, y], axis=-1)
    half_l = (length / 2)[:, None]
    half_w = (width / 2)[:, None]
    return np.stack(
        [
            centre + forward * half_l + left * half_w,
            centre - forward * half_l + left * half_w,
            centre - forward * half_l - left * half_w,
            centre + forward * half_l - left * half_w,
        ],
        axis=1,
    )
