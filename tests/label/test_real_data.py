"""The labeller on real recordings, against facts checked by hand (issue 5's validation list).

* nuScenes scene-0061: the ego turns left (heading +98 degrees) through the intersection lanes
  between about 6 s and 13 s; scene-0916: it turns right (-144 degrees) from the start to about
  10 s; scene-0553: it does not move (0.0 m).
* CommonRoad NGSIM: following each vehicle's lanelet (the map lane it is in), the moves to a
  same-direction neighbour lanelet outside intersections are US101-3_3: one to the left (the
  file's LANE_CHANGE tag), US101-4_1: one to the right, Lanker-1_1: one each way; Peach-4_8's
  only such move happens inside an intersection during a left turn (overlapping lanelets).
* AV2: both sensor logs' ego vehicles follow their lanes (7fab2350 stops at an intersection and
  starts a left turn; adcf7d18 starts from standstill).
"""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.label import label_trace
from scenegrep.model.layers import UnknownLayers
from scenegrep.readers import read_map, read_trace

pytestmark = pytest.mark.real_data

NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"


def labelled(path):
    """The labelled trace; nuScenes maps publish no crosswalks, taken as none (strict): these tests
    check vehicles' labels, which do not read crosswalks."""
    trace = read_trace(path)
    return label_trace(trace, read_map(trace.map_source), unknown_layers=UnknownLayers("strict"))


def ego_sets(labelling):
    trace = labelling.trace
    rows = np.flatnonzero(trace.states.object == trace.object_index(trace.ego))
    sets = trace.behaviours.sets()
    return [sets[i] for i in rows], labelling.in_intersection[rows]


def test_nuscenes_0061_ego_turns_left_through_the_intersection(real_data):
    sets, inside = ego_sets(labelled(real_data / NUSC.format("0061")))
    turning = np.array(["TurnLeft" in s for s in sets])
    assert turning[65:125].all() and not turning[:55].any() and not turning[135:].any()
    assert inside[turning].any() and not any("TurnRight" in s for s in sets)
    assert all("FollowLane" in s for s in sets)


def test_nuscenes_0916_ego_turns_right(real_data):
    sets, _ = ego_sets(labelled(real_data / NUSC.format("0916")))
    turning = np.array(["TurnRight" in s for s in sets])
    assert turning[:90].all() and not turning[100:].any()
    assert not any("TurnLeft" in s for s in sets)


def test_nuscenes_0553_ego_is_stationary_throughout(real_data):
    labelling = labelled(real_data / NUSC.format("0553"))
    sets, _ = ego_sets(labelling)
    assert len(sets) == labelling.trace.n_frames and set(sets) == {frozenset({"Stationary"})}


def lane_change_runs(labelling, behaviour):
    """(first, last) track positions of every run of ``behaviour`` in the label sets."""
    tracks = labelling.tracks
    labels = labelling.trace.behaviours
    flags = labels.member[tracks.order, labels.vocabulary.index(behaviour)]
    first, last = tracks.runs(flags)
    return sorted({(int(first[p]), int(last[p])) for p in np.flatnonzero(flags)})


@pytest.mark.parametrize(
    ("name", "left", "right"),
    [("US101-3_3", 1, 0), ("US101-4_1", 0, 1), ("Lanker-1_1", 1, 1), ("Peach-4_8", 0, 0)],
)
def test_commonroad_lane_changes_agree_with_the_lanelet_adjacency(real_data, name, left, right):
    labelling = labelled(real_data / f"commonroad_ngsim/USA_{name}_T-1.xml")
    e = labelling.evidence
    outside = ~e.in_intersection
    assert (int((e.change_left & outside).sum()), int((e.change_right & outside).sum())) == (left, right)
    for events, behaviour in (
        (e.change_left & outside, "LaneChangeLeft"),
        (e.change_right & outside, "LaneChangeRight"),
    ):
        runs = lane_change_runs(labelling, behaviour)
        for position in np.flatnonzero(events):
            # every adjacency move is inside a labelled change lasting at least a second (or the whole
            # observed part of the track, for tracks that begin or end during the change)
            start, end = labelling.tracks.start[position], labelling.tracks.end[position] - 1
            assert any(a <= position <= b and (b - a >= 10 or a == start or b == end) for a, b in runs)


def test_commonroad_us101_3_3_has_one_left_lane_change(real_data):
    labelling = labelled(real_data / "commonroad_ngsim/USA_US101-3_3_T-1.xml")
    assert len(lane_change_runs(labelling, "LaneChangeLeft")) == 1


@pytest.mark.parametrize("log", ["7fab2350-7eaf-3b7e-a39d-6937a4c1bede", "adcf7d18-0510-35b0-a2fa-b4cea13a6d76"])
def test_av2_ego_follows_its_lane(real_data, log):
    labelling = labelled(real_data / "av2/sensor" / log)
    sets, _ = ego_sets(labelling)
    trace = labelling.trace
    rows = trace.states.object == trace.object_index(trace.ego)
    speed = labelling.tracks.to_rows(labelling.evidence.speed)[rows]
    moving = speed > 1.0
    assert moving.sum() > 80
    assert all("FollowLane" in s for s, m in zip(sets, moving) if m)
    assert sum(any(b.startswith("LaneChange") for b in s) for s in sets) <= 0.05 * len(sets)
