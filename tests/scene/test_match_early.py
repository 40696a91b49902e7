"""Groups without random variables checked early (:func:`scenegrep.scene.match.match_trace`):
the same matches, surviving rows and first failing groups (what ``--explain`` names) as in the
documented order, on Town01 frames of examples/scenes/following_curb.scenic (a car walked back
20-30 m from a random curb point, Scenic's rule) planted, moved and turned (a frame moved off the
map and turned fails its position group first, though its heading group, checked early, refutes
it); with a choice for unknown layers nothing is checked early."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions, Tolerance, load_scene
from scenegrep.scene.follow import walk_end
from scenegrep.scene.match import match_trace
from tests.scene.frames import trace_of
from tests.scene.test_follow import FIELD
from tests.scene.test_follow_start import town01

PROGRAM = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "following_curb.scenic"
MOVES = st.sampled_from([(0.0, 0.0, 0.0), (0.0, 0.0, 0.3), (3.0, 0.0, 0.0), (0.0, 3.0, 0.3), (500.0, 500.0, 0.3)])


@cache
def walks():
    """20 walks from random Town01 curb points, D in [-30, -20]: (x, y, heading) of each end, and
    an ego pose on a lane."""
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    geometry = found[0]
    curbs = geometry.map.curb_polylines
    rng = np.random.default_rng(17)
    k = rng.integers(len(curbs.start), size=20)
    t = rng.random(20)[:, None]
    start = curbs.start[k] + t * (curbs.end[k] - curbs.start[k])
    ex, ey = walk_end(geometry, FIELD, start[:, 0], start[:, 1], rng.uniform(-30, -20, 20), None)
    heading = geometry.scenic_headings(FIELD, ex, ey, None)
    lane = geometry.map.centreline_polylines
    ego = lane.start[0] + 0.5 * (lane.end[0] - lane.start[0])
    ego_heading = geometry.scenic_headings(FIELD, ego[:1], ego[1:], None)[0]
    return geometry, np.stack([ex, ey, heading], 1), (float(ego[0]), float(ego[1]), float(ego_heading))


def both(picks, unknown: UnknownLayers | None = None):
    """The matches of one frame per (walk index, dx, dy, turn), early and in the documented order."""
    geometry, ends, ego = walks()
    frames = [
        {"ego": ("Car", *ego), "obj1": ("Car", ends[i, 0] + dx, ends[i, 1] + dy, ends[i, 2] + turn)}
        for i, (dx, dy, turn) in picks
    ]
    trace = trace_of(*frames)
    options = SceneOptions(Tolerance(), correspondence={"ego": "ego", "otherCar": "obj1"}, unknown_layers=unknown)
    compiled = load_scene(PROGRAM).for_map(geometry)
    groups = compiled.groups_for(trace)
    return [match_trace(compiled.program, groups, trace, geometry, options, early) for early in (True, False)]


@pytest.mark.real_data
@settings(max_examples=8, deadline=None, derandomize=True)
@given(st.lists(st.tuples(st.integers(0, 19), MOVES), min_size=1, max_size=4))
def test_early_checks_change_no_answer_and_no_failing_group(picks):
    early, ordered = both(picks)
    assert np.array_equal(early.matched, ordered.matched)
    assert np.array_equal(early.failed_group, ordered.failed_group)
    assert np.array_equal(early.survivors.frame, ordered.survivors.frame)
    assert {k: v.tolist() for k, v in early.every.state.items()} == {
        k: v.tolist() for k, v in ordered.every.state.items()
    }


@pytest.mark.real_data
def test_a_frame_moved_off_and_turned_fails_its_position_first():
    """A planted walk (one whose car lies on the road: some others overhang it), turned only, and
    moved 500 m and turned: the first matches; the heading group refutes the others early, without
    the walk's solver, and the first failing group of the moved one is still the position's (found
    again in order when asked); with a choice for unknown layers the solver decides the turned one
    too."""
    early, ordered = both([(1, (0.0, 0.0, 0.0)), (1, (0.0, 0.0, 0.3)), (1, (500.0, 500.0, 0.3))])
    groups = [g.describe() for g in early.groups]
    assert early.matched.tolist() == [True, False, False]
    assert [groups[g] for g in early.failed_group[1:]] == ["otherCar.heading", "otherCar.x, otherCar.y"]
    assert np.array_equal(early.failed_group, ordered.failed_group)
    assert sum(early.notes.values()) == 1 and sum(ordered.notes.values()) == 3
    chosen, _ = both([(1, (0.0, 0.0, 0.0)), (1, (0.0, 0.0, 0.3))], UnknownLayers("permissive"))
    assert sum(chosen.notes.values()) == 2
