"""Angle conventions (Scenic's: 0 = +y, counter-clockwise, (-pi, pi]) and box geometry."""

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.model.geometry import (
    box_corners,
    heading_difference,
    heading_from_atan2,
    heading_from_yaw,
    heading_of_vector,
    normalize_angle,
    rotation_matrices,
    yaw_from_heading,
    yaw_from_quaternion,
)

angles = st.floats(-50, 50, allow_nan=False)


def test_heading_of_segment_matches_scenic_example():
    # docs/scenic-reference.md: headingOfSegment((0,0),(3,4)) = -0.6435
    assert math.isclose(float(heading_of_vector(3, 4)), math.atan2(-3, 4), abs_tol=1e-12)
    assert round(float(heading_of_vector(3, 4)), 4) == -0.6435


def test_heading_from_atan2_is_heading_from_yaw_bit_for_bit():
    rng = np.random.default_rng(7)
    edges = [-math.pi, math.pi, -0.0, 0.0, -math.pi / 2, math.pi / 2, 3 * math.pi / 4, -3 * math.pi / 4, math.nan]
    edges += [np.nextafter(e, d) for e in edges[:-1] for d in (-4.0, 4.0) if -math.pi <= np.nextafter(e, d) <= math.pi]
    yaws = np.concatenate([edges, np.arctan2(rng.normal(size=200_000), rng.normal(size=200_000))])
    expected = heading_from_yaw(yaws)
    got = heading_from_atan2(yaws.copy())
    np.testing.assert_array_equal(got.view(np.int64), expected.view(np.int64))  # (bits: signs of zero too)


def test_cardinal_directions():
    assert heading_of_vector(0, 1) == 0.0
    assert math.isclose(heading_of_vector(-1, 0), math.pi / 2)
    assert math.isclose(heading_from_yaw(0.0), -math.pi / 2)  # east
    assert math.isclose(heading_from_yaw(math.pi / 2), 0.0)  # north


@given(angles)
def test_normalize_range_and_equivalence(a):
    n = float(normalize_angle(a))
    assert -math.pi < n <= math.pi
    assert math.isclose(math.cos(n), math.cos(a), abs_tol=1e-9) and math.isclose(math.sin(n), math.sin(a), abs_tol=1e-9)


def test_normalize_pi_boundary():
    assert normalize_angle(-math.pi) == math.pi and normalize_angle(math.pi) == math.pi


@given(angles)
def test_yaw_heading_round_trip(yaw):
    assert math.isclose(float(yaw_from_heading(heading_from_yaw(yaw))), float(normalize_angle(yaw)), abs_tol=1e-9)


@given(angles)
def test_heading_points_along_yaw_direction(yaw):
    h = heading_from_yaw(yaw)
    assert abs(float(heading_difference(h, heading_of_vector(math.cos(yaw), math.sin(yaw))))) < 1e-9


@given(angles, angles)
def test_heading_difference_is_smallest_rotation(a, b):
    d = float(heading_difference(a, b))
    assert -math.pi < d <= math.pi
    assert (
        abs(float(normalize_angle(b + d - a))) < 1e-9
        or abs(abs(float(normalize_angle(b + d - a))) - 2 * math.pi) < 1e-9
    )


@given(angles)
def test_quaternion_yaw_and_matrix(yaw):
    qw, qz = math.cos(yaw / 2), math.sin(yaw / 2)
    assert abs(float(heading_difference(yaw_from_quaternion(qw, 0, 0, qz), yaw))) < 1e-9
    r = rotation_matrices(qw, 0, 0, qz)[0]
    assert np.allclose(r @ [1, 0, 0], [math.cos(yaw), math.sin(yaw), 0])


def test_box_corners_front_is_along_heading():
    corners = box_corners(10, 20, heading_from_yaw(0.0), 4.0, 2.0)[0]  # facing east
    assert np.allclose(corners, [[12, 21], [8, 21], [8, 19], [12, 19]])
