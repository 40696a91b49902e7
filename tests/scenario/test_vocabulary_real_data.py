"""The named primitives of the vocabulary on real recordings (issue 16): each query's answer is
checked against facts computed here from the raw numbers (positions, headings, times), not by
another run of scenegrep. The recordings are labelled as ``scenegrep scenario`` labels them.

Facts, read off the raw data below (headings in Scenic's convention: counter-clockwise positive):

* nuScenes scene-0061: the ego's heading grows by 0.84 rad over the 4 s around frame 95 (a left
  turn) and never shrinks over any 4 s; scene-0916: it shrinks by 1.46 rad around frame 77 (a
  right turn).
* CommonRoad US101-3_3 (a straight highway): vehicle 394 moves 2.0 m to the left across the road in
  3.1 s, no other vehicle more than 0.7 m either way; US101-4_1: vehicle 389 moves 1.7 m to the
  right within 2 s, no other vehicle more than 0.8 m in any 2 s.
* AV2 7fab2350: the ego slows from 10 m/s to a stop between frames 20 and 100; vehicle 688118c3
  moves backwards (against its own heading) at 0.4-0.8 m/s around frames 90-125.
  AV2 adcf7d18: the ego stands for 4.5 s, then speeds up from 0 to 4.7 m/s in 3 s.
* nuScenes scene-0061: pedestrians walk at over 1 m/s for the whole scene while others stand.
* AV2 adcf7d18: pedestrians walk over the map's pedestrian crossings.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest
import shapely

from scenegrep.label import label_trace
from scenegrep.model import LabelTrace, RoadMap
from scenegrep.model.layers import UnknownLayers
from scenegrep.readers import read_map, read_trace
from scenegrep.scenario import ScenarioOptions, compile_scenario
from tests.conftest import SHARED

pytestmark = pytest.mark.real_data

HEADER = "model scenic.simulators.newtonian.driving_model\n"
FREE = "with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere"
"""A car that turns, changes lanes or reverses does not face along its road, nor always keep its
box on the road (a car backing out of a drive), as Scenic's defaults say."""
NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"
AV2_BRAKE_REVERSE = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
AV2_START_CROSS = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"
CHOICE = "permissive"
"""Map layers the recordings do not publish (nuScenes crosswalks, sidewalks) are everywhere: a
pedestrian may stand anywhere; the labeller's Cross rule then reads a crossing everywhere, so
the Cross checks use AV2, whose maps publish crossings."""


@cache
def raw(relative: str) -> LabelTrace:
    """A real recording as read, once per process (the tests only read it)."""
    return read_trace(SHARED / "real_data" / relative)


@cache
def recording(relative: str) -> tuple[LabelTrace, RoadMap | None]:
    """A real recording, labelled as ``scenegrep scenario`` labels it, and its map."""
    trace = raw(relative)
    road_map = read_map(trace.map_source) if trace.map_source is not None else None
    return label_trace(trace, road_map, unknown_layers=UnknownLayers(CHOICE)).trace, road_map


def answers(relative: str, objects: str, window: int, name: str = "x") -> dict[str, list[int]]:
    """Program object ``name``'s label object id -> the starts of its matching windows, for the
    program ``objects`` (Scenic lines after the model line)."""
    trace, road_map = recording(relative)
    query = compile_scenario(HEADER + objects)
    options = ScenarioOptions(find_all=True, unknown_layers=UnknownLayers(CHOICE))
    found: dict[str, list[int]] = {}
    for match in query.match(trace, window, road_map=road_map, options=options).matches:
        found.setdefault(match.correspondence[name], []).extend(int(s) for s in match.starts)
    return found


def ego_answers(relative: str, primitive: str, window: int) -> list[int]:
    """Starts of the windows in which the recording's ego runs ``primitive``."""
    trace = recording(relative)[0]
    assert trace.ego is not None
    return answers(relative, f"ego = new Car with behavior {primitive}Behavior(), {FREE}\n", window, "ego").get(
        trace.ego, []
    )


def other_answers(relative: str, kind: str, primitive: str, window: int) -> dict[str, list[int]]:
    """Objects other than the ego running ``primitive``, whatever the ego does (AnyBehavior)."""
    free = f", {FREE}" if kind == "Car" else ""
    program = (
        f"ego = new Car with behavior AnyBehavior(), {FREE}\nx = new {kind} with behavior {primitive}Behavior(){free}\n"
    )
    return answers(relative, program, window)


def raw_track(relative: str, object_id: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Frames, times (s), x, y (m) and headings (rad) of one object, as recorded, in time order."""
    trace = raw(relative)
    rows = np.flatnonzero(trace.states.object == trace.object_index(object_id))
    rows = rows[np.argsort(trace.states.frame[rows])]
    s = trace.states
    return s.frame[rows], trace.frame_time[s.frame[rows]], s.x[rows], s.y[rows], s.heading[rows]


def four_second_turn(heading: np.ndarray, half: int = 20) -> np.ndarray:
    """Per frame, the heading change (rad) from ``half`` frames before to ``half`` after (clipped)."""
    u = np.unwrap(heading)
    n = len(u)
    return np.array([u[min(i + half, n - 1)] - u[max(i - half, 0)] for i in range(n)])


def speeds(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.hypot(np.gradient(x, t), np.gradient(y, t))


def covered(starts: list[int], window: int) -> set[int]:
    return {f for s in starts for f in range(s, s + window)}


# ---------------------------------------------------------------- turns
def test_turn_left_finds_the_left_turn_of_nuscenes_0061():
    relative = NUSC.format("0061")
    frames, _, _, _, heading = raw_track(relative, "ego")
    turn = four_second_turn(heading)
    peak = int(np.argmax(turn))
    assert peak == 95 and turn[peak] > 0.8 and (turn > 0).all()  # counter-clockwise only
    starts = ego_answers(relative, "TurnLeft", 30)
    assert peak - 15 in starts
    assert all(turn[f] > 0.3 for f in covered(starts, 30))
    assert ego_answers(relative, "TurnRight", 10) == []  # never clockwise


def test_turn_right_finds_the_right_turn_of_nuscenes_0916():
    relative = NUSC.format("0916")
    _, _, _, _, heading = raw_track(relative, "ego")
    turn = four_second_turn(heading)
    trough = int(np.argmin(turn))
    assert trough == 77 and turn[trough] < -1.4
    starts = ego_answers(relative, "TurnRight", 20)
    assert trough - 10 in starts
    assert all(turn[f] < -0.3 for f in covered(starts, 20))


# ---------------------------------------------------------------- lane changes
def leftward_offsets(relative: str) -> dict[str, np.ndarray]:
    """Per vehicle, its position across the road (m, towards the left of the traffic), frame by frame:
    the road is straight, so its direction is the mean of every recorded heading."""
    trace = raw(relative)
    s = trace.states
    road = np.arctan2(np.sin(s.heading).mean(), np.cos(s.heading).mean())
    offsets = {}
    for k, object_id in enumerate(trace.objects.id):
        rows = np.flatnonzero(s.object == k)
        rows = rows[np.argsort(s.frame[rows])]
        offsets[str(object_id)] = -np.cos(road) * s.x[rows] - np.sin(road) * s.y[rows]
    return offsets


def moves(offsets: dict[str, np.ndarray], window: int) -> dict[str, tuple[float, float]]:
    """Per vehicle, the largest move (m) to the left and to the right within ``window`` frames."""
    out = {}
    for name, d in offsets.items():
        steps = [d[i + window - 1] - d[i] for i in range(len(d) - window + 1)] or [0.0]
        out[name] = (max(steps), -min(steps))
    return out


def test_lane_change_left_finds_the_one_vehicle_moving_left_on_us101_3_3():
    relative = "commonroad_ngsim/USA_US101-3_3_T-1.xml"
    move = moves(leftward_offsets(relative), 32)
    assert {name for name, (left, _) in move.items() if left > 1.0} == {"394"}
    assert max(max(left, right) for name, (left, right) in move.items() if name != "394") < 0.7
    found = answers(relative, f"ego = new Car with behavior LaneChangeLeftBehavior(), {FREE}\n", 32, "ego")
    assert set(found) == {"394"}
    assert answers(relative, f"ego = new Car with behavior LaneChangeRightBehavior(), {FREE}\n", 32, "ego") == {}


def test_lane_change_right_finds_the_one_vehicle_moving_right_on_us101_4_1():
    relative = "commonroad_ngsim/USA_US101-4_1_T-1.xml"
    move = moves(leftward_offsets(relative), 20)
    assert {name for name, (_, right) in move.items() if right > 1.0} == {"389"}
    assert max(right for name, (_, right) in move.items() if name != "389") < 0.8
    found = answers(relative, f"ego = new Car with behavior LaneChangeRightBehavior(), {FREE}\n", 20, "ego")
    assert set(found) == {"389"}
    assert "389" not in answers(relative, f"ego = new Car with behavior LaneChangeLeftBehavior(), {FREE}\n", 20, "ego")


# ---------------------------------------------------------------- speed changes
def test_brake_finds_the_av2_ego_slowing_to_a_stop():
    frames, t, x, y, _ = raw_track(AV2_BRAKE_REVERSE, "ego")
    v = speeds(t, x, y)
    assert v[20] > 10 and v[100] < 0.5
    window = 20
    drop = np.array([v[i] - v[i + window - 1] for i in range(len(v) - window + 1)])
    starts = ego_answers(AV2_BRAKE_REVERSE, "Brake", window)
    assert starts and min(abs(s - int(np.argmax(drop))) for s in starts) <= 3
    assert all(drop[s] > 1.0 for s in starts)  # every answer loses over 1 m/s in its 2 s
    assert ego_answers(AV2_BRAKE_REVERSE, "Accelerate", 40) == []


def test_accelerate_finds_the_av2_ego_starting_from_standstill():
    frames, t, x, y, _ = raw_track(AV2_START_CROSS, "ego")
    v = speeds(t, x, y)
    assert (v[:45] < 0.1).all() and v[80] > 4.5
    window = 20
    gain = np.array([v[i + window - 1] - v[i] for i in range(len(v) - window + 1)])
    starts = ego_answers(AV2_START_CROSS, "Accelerate", window)
    assert starts and min(abs(s - int(np.argmax(gain))) for s in starts) <= 3
    assert all(gain[s] > 1.0 for s in starts)
    assert ego_answers(AV2_START_CROSS, "Brake", 40) == []


def test_reverse_finds_the_av2_vehicle_moving_backwards():
    window = 20
    found = other_answers(AV2_BRAKE_REVERSE, "Car", "Reverse", window)
    reversing = next(name for name in found if name.startswith("688118c3"))
    frames, t, x, y, heading = raw_track(AV2_BRAKE_REVERSE, reversing)
    along = -np.sin(heading) * np.gradient(x, t) + np.cos(heading) * np.gradient(y, t)
    at = dict(zip(frames.tolist(), along.tolist()))
    assert max(at[f] for f in range(95, 116)) < -0.4  # backwards, against its own heading
    for name, starts in found.items():
        f, t, x, y, h = raw_track(AV2_BRAKE_REVERSE, name)
        speed_along = dict(zip(f.tolist(), (-np.sin(h) * np.gradient(x, t) + np.cos(h) * np.gradient(y, t)).tolist()))
        assert all(np.mean([speed_along[g] for g in range(s, s + window)]) < -0.3 for s in starts), name
    _, t, x, y, h = raw_track(AV2_BRAKE_REVERSE, "ego")
    assert (-np.sin(h) * np.gradient(x, t) + np.cos(h) * np.gradient(y, t) > -0.1).all()
    assert ego_answers(AV2_BRAKE_REVERSE, "Reverse", 5) == []


# ---------------------------------------------------------------- pedestrians
def test_walk_finds_walking_pedestrians_and_not_standing_ones():
    relative = NUSC.format("0061")
    window = 50
    found = other_answers(relative, "Pedestrian", "Walk", window)
    trace = raw(relative)
    walking, standing = set(), set()
    for k, object_id in enumerate(trace.objects.id):
        f, t, x, y, _ = raw_track(relative, str(object_id))
        if not str(trace.objects.category[k]).startswith("human.pedestrian") or len(f) < window:
            continue
        v = speeds(t, x, y)
        if any(
            (v[i : i + window] > 0.8).all() and f[i + window - 1] - f[i] == window - 1
            for i in range(len(f) - window + 1)
        ):
            walking.add(str(object_id))
        if v.max() < 0.2:
            standing.add(str(object_id))
    assert len(walking) >= 2 and len(standing) >= 2
    assert walking <= set(found) and not standing & set(found)
    for name, starts in found.items():
        f, t, x, y, _ = raw_track(relative, name)
        at = dict(zip(f.tolist(), speeds(t, x, y).tolist()))
        assert all(np.mean([at[g] for g in range(s, s + window)]) > 0.3 for s in starts), name


def test_cross_finds_pedestrians_on_the_av2_crossings():
    window = 20
    trace, road_map = recording(AV2_START_CROSS)
    assert road_map is not None and road_map.crosswalks and road_map.drivable_area is not None
    crossings = shapely.union_all([area.polygon for area in road_map.crosswalks])
    found = other_answers(AV2_START_CROSS, "Pedestrian", "Cross", window)
    on_crossing, off_road = set(), set()
    for k, object_id in enumerate(trace.objects.id):
        if trace.objects.category[k] != "PEDESTRIAN":
            continue
        f, t, x, y, _ = raw_track(AV2_START_CROSS, str(object_id))
        inside = shapely.contains_xy(crossings, x, y)
        on_road = inside | shapely.contains_xy(road_map.drivable_area, x, y)
        v = speeds(t, x, y)
        if any((inside & (v > 0.8))[i : i + window].all() for i in range(len(f) - window + 1)):
            on_crossing.add(str(object_id))
        if not on_road.any() and np.median(v) > 0.8:
            off_road.add(str(object_id))
        road_at = dict(zip(f.tolist(), on_road.tolist()))
        for start in found.get(str(object_id), []):
            assert np.mean([road_at[g] for g in range(start, start + window)]) >= 0.5, object_id
    assert len(on_crossing) >= 2 and len(off_road) >= 2
    assert on_crossing <= set(found) and not off_road & set(found)


@pytest.fixture(autouse=True)
def _shared(real_data: Path) -> None:
    """Skip when ../shared/real_data is absent."""
