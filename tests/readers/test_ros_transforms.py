"""The tf buffer: a chain of links interpolated at any stamp (linear translation, slerp rotation),
against a 2-D reference computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.readers.ros.messages import Transforms
from scenegrep.readers.ros.transforms import MissingTransform, TfBuffer, _Link, yaw_of

coordinate = st.floats(-1e4, 1e4)
angle = st.floats(-math.pi, math.pi)


def _links(parent: str, child: str, stamps, xy, yaws) -> Transforms:
    n = len(stamps)
    xyz = np.column_stack([np.asarray(xy, dtype=float).reshape(n, 2), np.zeros(n)])
    half = np.asarray(yaws, dtype=float) / 2
    quat = np.column_stack([np.zeros(n), np.zeros(n), np.sin(half), np.cos(half)])
    names = np.full(n, parent, dtype=object), np.full(n, child, dtype=object)
    return Transforms(np.arange(n), np.asarray(stamps, dtype=np.int64), *names, xyz, quat)


@given(
    static=st.tuples(coordinate, coordinate, angle),
    start=st.tuples(coordinate, coordinate, angle),
    end=st.tuples(coordinate, coordinate, st.floats(-3.0, 3.0)),
    fraction=st.floats(0.0, 1.0),
)
def test_a_chain_interpolates_like_the_hand_computation(static, start, end, fraction):
    buffer = TfBuffer()
    buffer.add(_links("map", "odom", [0], [static[:2]], [static[2]]), static=True)
    turn = end[2]  # the second sample turns by less than pi: slerp's short way is this way
    buffer.add(_links("odom", "base_link", [1_000, 3_000], [start[:2], end[:2]], [start[2], start[2] + turn]))
    stamp = 1_000 + round(2_000 * fraction)
    t = (stamp - 1_000) / 2_000
    xyz, quat = buffer.lookup("base_link", "map", np.array([stamp]))
    local = np.array(start[:2]) + t * (np.array(end[:2]) - np.array(start[:2]))
    c, s = math.cos(static[2]), math.sin(static[2])
    expected = np.array([c * local[0] - s * local[1] + static[0], s * local[0] + c * local[1] + static[1]])
    np.testing.assert_allclose(xyz[0, :2], expected, atol=1e-6)
    yaw = static[2] + start[2] + t * turn
    assert abs(math.remainder(float(yaw_of(quat)[0]) - yaw, 2 * math.pi)) < 1e-6


def test_a_stamp_outside_the_samples_or_without_a_chain_is_missing():
    buffer = TfBuffer()
    buffer.add(_links("map", "base_link", [100, 200], [(0, 0), (1, 0)], [0, 0]))
    xyz, _ = buffer.lookup("base_link", "map", np.array([100, 150, 200]))
    np.testing.assert_allclose(xyz[:, 0], [0, 0.5, 1])
    with pytest.raises(MissingTransform) as error:
        buffer.lookup("base_link", "map", np.array([150, 201]))
    assert error.value.row == 1 and "known from 100 to 200 ns" in error.value.reason
    with pytest.raises(MissingTransform, match="no transform chain from frame 'lidar'"):
        buffer.lookup("lidar", "map", np.array([150]))
    assert buffer.latest("base_link", "map") == 200 and buffer.latest("lidar", "map") is None


def test_a_cycle_is_no_chain():
    buffer = TfBuffer()
    buffer.add(_links("a", "b", [0], [(0, 0)], [0]))
    buffer.add(_links("b", "a", [0], [(0, 0)], [0]))
    assert buffer.chain("a", "map") is None


@settings(max_examples=60, deadline=None)
@given(st.lists(st.lists(st.integers(0, 20), max_size=6), min_size=1, max_size=5), st.lists(st.booleans(), max_size=5))
def test_a_link_keeps_the_last_sample_received_per_stamp_however_it_is_fed(batches, reads):
    link, received = _Link("map", False), []
    for k, stamps in enumerate(batches):
        xyz = np.array([[len(received) + j, 0.0, 0.0] for j in range(len(stamps))]).reshape(-1, 3)
        link.add(np.array(stamps, dtype=np.int64), xyz, np.tile([0.0, 0.0, 0.0, 1.0], (len(stamps), 1)), None)
        received += stamps
        if k < len(reads) and reads[k] and received:
            assert link.last() == max(received)  # read between batches, or not
    if not received:
        return
    stamps, xyz, _, velocity = link.arrays()
    last = {stamp: i for i, stamp in enumerate(received)}
    assert stamps.tolist() == sorted(last) and link.last() == max(received)
    assert xyz[:, 0].tolist() == [last[s] for s in sorted(last)]
    assert np.isnan(velocity).all()
