"""Every labelling rule on hand-built tracks whose behaviour is known by construction."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scenegrep.label import VOCABULARY, label_trace, load_config
from tests.label.tracks import DT, neighbour_map, sets_of, trace_of
from tests.model.maps import synthetic_map

MAP = neighbour_map()


def steps(seconds: float) -> np.ndarray:
    return np.arange(round(seconds / DT) + 1) * DT


def straight(speed: float, seconds: float = 6.0, x: float = 1.75, y0: float = 5.0) -> tuple:
    t = steps(seconds)
    return ("car", np.full(len(t), x), y0 + speed * t, None)


def labelled(*tracks, road_map=MAP, **options):
    return label_trace(trace_of(*tracks), road_map, **options).trace


def test_a_car_driving_along_its_lane_follows_it():
    assert set(sets_of(labelled(straight(10.0)))) == {frozenset({"FollowLane"})}


def test_a_parked_car_is_stationary():
    assert set(sets_of(labelled(straight(0.0)))) == {frozenset({"Stationary"})}


def test_a_slow_car_is_both_stationary_and_following():
    # 0.55 m/s lies inside the stationary ramp [0.8, 0.3]: both readings are plausible
    assert set(sets_of(labelled(straight(0.55)))) == {frozenset({"Stationary", "FollowLane"})}


def test_a_change_to_the_right_neighbour_lane():
    t = steps(8.0)
    x = 1.75 + 3.5 * np.clip((t - 3.0) / 3.0, 0.0, 1.0)  # n1 -> n2 between 3 s and 6 s, past the intersection
    sets = sets_of(labelled(("car", x, 55.0 + 5.0 * t, None)))
    during = [sets[k] for k in range(len(t)) if 3.7 <= t[k] <= 5.3]
    outside = [sets[k] for k in range(len(t)) if t[k] <= 1.5 or t[k] >= 7.5]
    assert all("LaneChangeRight" in s for s in during)
    assert not any("LaneChange" in name for s in outside for name in s)
    assert not any("LaneChangeLeft" in s for s in sets)


def test_lateral_drift_without_a_neighbour_lane_is_less_certain():
    t = steps(8.0)
    drift = 1.2 * np.clip((t - 3.0) / 3.0, 0.0, 1.0)  # towards the oncoming lane on the left, n2 on the right

    def peak(x, behaviour):
        labelling = label_trace(trace_of(("car", x, 55.0 + 5.0 * t, None)), MAP, min_confidence=1e-9)
        return np.nanmax(labelling.trace.behaviours.confidence[:, VOCABULARY.index(behaviour)])

    left, right = peak(1.75 - drift, "LaneChangeLeft"), peak(1.75 + drift, "LaneChangeRight")
    assert right > 0 and left == pytest.approx(load_config().vehicle.no_neighbour_factor * right, rel=1e-5)


def test_braking_and_accelerating():
    t = steps(6.0)
    y = 5.0 + 15.0 * t - 0.5 * 2.5 * t**2  # 15 m/s braking at 2.5 m/s2
    sets = sets_of(labelled(("car", np.full(len(t), 1.75), y, None)))
    assert all("Brake" in s and "Accelerate" not in s for s in sets[10:-10])
    y = 5.0 + 2.0 * t + 0.5 * 2.5 * t**2
    sets = sets_of(labelled(("car", np.full(len(t), 1.75), y, None)))
    assert all("Accelerate" in s and "Brake" not in s for s in sets[10:-10])


def test_reversing_against_the_own_heading():
    t = steps(5.0)
    sets = sets_of(labelled(("car", np.full(len(t), 1.75), 60.0 - 2.0 * t, np.zeros(len(t)))))
    assert all("Reverse" in s and "FollowLane" not in s for s in sets)


def right_turn() -> tuple:
    """Northbound on n1 to the intersection lane x1, then a quarter circle to the east."""
    t = steps(9.0)
    speed, radius = 5.0, 6.0
    centre = (1.75 + radius, 45.0)
    arc_time = (math.pi / 2) * radius / speed
    angle = np.clip((t - 3.0) / arc_time, 0.0, 1.0) * (math.pi / 2)
    before, after = t < 3.0, t > 3.0 + arc_time
    x = np.where(before, 1.75, centre[0] - radius * np.cos(angle))
    y = np.where(before, 30.0 + speed * t, centre[1] + radius * np.sin(angle))
    x = np.where(after, centre[0] + speed * (t - 3.0 - arc_time), x)
    y = np.where(after, centre[1] + radius, y)
    return ("car", x, y, None)


def test_a_right_turn_near_an_intersection():
    sets = sets_of(labelled(right_turn()))
    assert sum("TurnRight" in s for s in sets) >= 15
    assert not any("TurnLeft" in s for s in sets)


def test_a_curve_far_from_intersections_is_not_a_turn():
    _, x, y, _ = right_turn()
    sets = sets_of(labelled(("car", x + 200.0, y + 200.0, None)))  # the same path off the map's intersections
    assert not any(name.startswith("Turn") for s in sets for name in s)


def test_without_a_map_a_turn_is_read_from_the_heading_alone():
    sets = sets_of(labelled(right_turn(), road_map=None))
    assert sum("TurnRight" in s for s in sets) >= 15
    assert not any("LaneChange" in name for s in sets for name in s)


def pedestrian(x0, y0, vx, vy, seconds=5.0):
    t = steps(seconds)
    return ("pedestrian", x0 + vx * t, y0 + vy * t, None)


def test_pedestrians_walk_stand_and_cross():
    trace = labelled(
        pedestrian(-3.0, 30.0, 1.4, 0.0),  # across the lanes
        pedestrian(-20.0, 10.0, 0.0, 1.4),  # along, off the road
        pedestrian(-3.0, 61.0, 0.0, 0.0),  # standing in the crosswalk
        pedestrian(-2.0, 10.0, 0.0, 1.4),  # along the lane, on it
    )
    assert set(sets_of(trace, 0)) == {frozenset({"Walk", "Cross"})}
    assert set(sets_of(trace, 1)) == {frozenset({"Walk"})}
    assert set(sets_of(trace, 2)) == {frozenset({"Stationary"})}
    assert set(sets_of(trace, 3)) == {frozenset({"Walk"})}


def test_a_single_observation_is_ambiguous():
    trace = labelled(("car", np.array([1.75]), np.array([20.0]), np.array([0.0])))
    assert sets_of(trace) == [frozenset({"Stationary", "FollowLane"})]


def test_a_higher_minimum_confidence_gives_subsets_never_empty():
    t = steps(8.0)
    x = 1.75 + 3.5 * np.clip((t - 3.0) / 3.0, 0.0, 1.0)
    tracks = (("car", x, 55.0 + 5.0 * t, None), straight(0.55, x=5.25), pedestrian(-3.0, 30.0, 0.3, 0.0))
    loose = labelled(*tracks, min_confidence=0.05).behaviours.sets()
    strict = labelled(*tracks, min_confidence=0.99).behaviours.sets()
    assert all(s <= ls and s for s, ls in zip(strict, loose))
    assert sum(map(len, strict)) < sum(map(len, loose))


def test_confidences_are_those_of_the_members():
    labels = labelled(straight(0.55), pedestrian(-3.0, 30.0, 1.4, 0.0)).behaviours
    assert np.array_equal(~np.isnan(labels.confidence), labels.member)
    assert np.all((labels.confidence[labels.member] > 0) & (labels.confidence[labels.member] <= 1))


def test_tracks_are_labelled_independently_of_each_other():
    tracks = (straight(10.0), right_turn(), pedestrian(-3.0, 30.0, 1.4, 0.0), straight(0.0, x=5.25))
    together = label_trace(trace_of(*tracks), MAP).trace
    for k, track in enumerate(tracks):
        alone = label_trace(trace_of(track), MAP).trace
        assert sets_of(together, k) == sets_of(alone)


def test_lanes_are_filled_from_the_map():
    trace = labelled(straight(10.0, seconds=12.0))
    names = trace.lane_names()
    assert set(names[:10].tolist()) == {"n1"} and names[-1] == "n1b"


@pytest.mark.parametrize("with_map", [True, False])
def test_intersection_flags_per_observation(with_map):
    labelling = label_trace(trace_of(straight(10.0, seconds=8.0)), synthetic_map() if with_map else None)
    y = labelling.trace.states.y
    expected = (y >= 50) & (y <= 53.5) if with_map else np.zeros(len(y), bool)
    assert np.array_equal(labelling.in_intersection, expected)
