"""Velocities by finite differences and the heading/motion check."""

import math

import numpy as np

from scenegrep.model import StateTable
from scenegrep.model.kinematics import finite_difference_velocity, heading_motion_error, with_derived_velocity


def test_velocity_central_and_one_sided_with_gaps():
    # object 0 moves +x at 10 m/s for frames 0..3; object 1 seen at frames 0 and 3 only (0.3 s gap > 0.25 limit)
    t = np.array([0.0, 0.1, 0.2, 0.3])
    states = StateTable.build([0, 1, 2, 3, 0, 3], [0, 0, 0, 0, 1, 1], [0, 1, 2, 3, 5, 5], [0] * 6, [0] * 6)
    vx, vy = finite_difference_velocity(states, t, max_gap_s=0.25)
    assert np.allclose(vx[:4], 10) and np.allclose(vy[:4], 0)
    assert np.isnan(vx[4]) and np.isnan(vx[5])


def test_with_derived_velocity_keeps_given_values():
    t = np.array([0.0, 1.0])
    states = StateTable.build([0, 1], [0, 0], [0, 2], [0, 0], [0, 0], vx=[7.0, np.nan], vy=[0.0, np.nan])
    out = with_derived_velocity(states, t)
    assert out.vx.tolist() == [7.0, 2.0]


def test_heading_motion_error():
    t = np.arange(3) * 0.1
    north = StateTable.build([0, 1, 2], [0, 0, 0], [0, 0, 0], [0, 1, 2], [0.0, 0.0, 0.0])
    backwards = StateTable.build([0, 1, 2], [0, 0, 0], [0, 0, 0], [0, 1, 2], [math.pi] * 3)
    assert np.allclose(heading_motion_error(north, t), 0)
    assert np.allclose(heading_motion_error(backwards, t), math.pi)
    slow = StateTable.build([0, 1, 2], [0, 0, 0], [0, 0, 0], [0, 0.01, 0.02], [0.0] * 3)
    assert np.isnan(heading_motion_error(slow, t)).all()
