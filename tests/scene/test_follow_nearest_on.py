"""The inverted walk's narrowing of a candidate segment's D interval to where its centreline's
nearest point may lie on it (:func:`scenegrep.scene.follow_inverse._narrowed`) never drops a
point the projection (:meth:`scenegrep.model.polylines.Polylines.segment_at`, the rule Scenic's
headings are read with) gives to that segment: on random points near Town01's lane and shoulder
centrelines, ties at vertices included; and the preimages of random Town01 walk ends equal those
computed without the narrowing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene import follow_inverse
from scenegrep.scene.follow_inverse import _narrowed, inverse, preimages
from tests.scene.test_follow import FIELD
from tests.scene.test_follow_start import town01, town01_walks


def geometry_or_skip():
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    return found[0]


@pytest.mark.real_data
@settings(max_examples=40, deadline=None, derandomize=True)
@given(st.integers(0, 10**6), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0), st.sampled_from([0.0, 0.5, 1.0]))
def test_the_segment_the_projection_picks_is_never_narrowed_away(seed, dx, dy, snap):
    """Points around a random vertex of a centreline (some exactly on the normals there, where the
    projection ties), each on a random path through it: the segment segment_at picks keeps the
    path's parameter of the point."""
    geometry = geometry_or_skip()
    road_map = geometry.map
    inv = inverse(geometry)
    rng = np.random.default_rng(seed)
    lanes = road_map.centreline_polylines
    line = int(rng.integers(len(lanes)))
    k = int(lanes.first[line] + rng.integers(lanes.count[line]))
    vertex = lanes.start[k] if snap == 0.0 else (lanes.end[k] if snap == 1.0 else (lanes.start[k] + lanes.end[k]) / 2)
    normal = np.array([-inv.unit[k, 1], inv.unit[k, 0]])
    offsets = np.concatenate([rng.normal(0, 1.5, (60, 2)), np.outer(rng.uniform(-3, 3, 20), normal)])
    points = vertex + np.array([dx, dy]) * 0.1 + offsets
    picked = lanes.segment_at(np.full(len(points), line), points[:, 0], points[:, 1])
    t = rng.uniform(0.0, 1.0, len(points))
    r = rng.normal(0, 4.0, (len(points), 2))
    p = points - t[:, None] * r
    a, z, anywhere = inv.ends[picked, :2], inv.ends[picked, 2:], np.full(len(p), np.inf)
    low, high = _narrowed(p, r, a, z, anywhere, inv.unit[picked], inv.before[picked], inv.after[picked])
    assert np.all((low <= t) & (t <= high)), points[~((low <= t) & (t <= high))]


@pytest.mark.real_data
def test_town01_preimages_equal_those_without_the_narrowing(monkeypatch):
    """60 random Town01 walks (starts near the roads, D forwards and backwards): with the first
    heading checked, the preimage of each end has the same rows of positive width as without the
    narrowing (every candidate's reach interval whole), to 1e-6 m in the D ends (roots found on
    another parametrisation; a piece at most 1e-9 m wide, D at a cut, may go); with it unchecked
    (a curb start's), each row lies within one of those; either way the walk's own start and
    distance are in it."""
    geometry, x, y, distance, ex, ey, lo, hi = town01_walks(16, 2000, 60)
    narrowed = [preimages(geometry, FIELD, ex, ey, lo, hi, check) for check in (True, False)]
    monkeypatch.setattr(follow_inverse, "_narrowed", lambda *rows: _narrowed(*rows, nearest=False))
    whole = [rows(preimages(geometry, FIELD, ex, ey, lo, hi, check)) for check in (True, False)]
    checked = rows(narrowed[0])
    wide = [table[table[:, 6] > table[:, 5] + 1e-9] for table in (checked, whole[0])]
    assert wide[0].shape == wide[1].shape
    np.testing.assert_allclose(wide[0], wide[1], rtol=0, atol=1e-6)
    unchecked = rows(narrowed[1])
    same = np.all(unchecked[:, None, :5] == whole[1][None, :, :5], axis=2)
    inside = (unchecked[:, None, 5] >= whole[1][None, :, 5] - 1e-9) & (
        unchecked[:, None, 6] <= whole[1][None, :, 6] + 1e-9
    )
    assert np.all(np.any(same & inside, axis=1))
    for pre in narrowed:
        at = (pre.lo <= distance[pre.row] + 1e-9) & (pre.hi >= distance[pre.row] - 1e-9)
        miss = np.hypot(
            ex[pre.row] + distance[pre.row] * pre.ax - x[pre.row], ey[pre.row] + distance[pre.row] * pre.ay - y[pre.row]
        )
        found = np.zeros(len(x), dtype=bool)
        found[pre.row[at & (miss <= 1e-6)]] = True
        assert found.all(), np.flatnonzero(~found)


def rows(pre) -> np.ndarray:
    """The preimage's rows (row, steps, ax, ay, first, lo, hi), sorted."""
    table = np.stack([pre.row, pre.steps, pre.ax, pre.ay, np.nan_to_num(pre.first, nan=9.0), pre.lo, pre.hi], 1)
    return table[np.lexsort(table.T[::-1])]
