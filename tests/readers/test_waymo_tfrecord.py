"""Waymo Open Motion Scenario TFRecords: counts verified on the real files, geometry
sanity (headings, lanes), map semantics, several scenarios per file, user errors,
and the round trip through scenegrep Parquet."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, RoadMap
from scenegrep.model.kinematics import heading_motion_error
from scenegrep.readers import detect_format
from scenegrep.readers import read_map as registry_read_map
from scenegrep.readers.tfrecord import read_records
from scenegrep.readers.waymo_tfrecord import FORMAT, MPH_TO_MPS, read_map, read_scenarios, read_traces

from .test_tfrecord import write_tfrecord

pytestmark = pytest.mark.real_data

ONE_SCENARIO = "motion_data_one_scenario.tfrecord"
SCENARIO_INPUT = "womd_scenario_input.tfrecord"


@pytest.fixture(scope="module")
def womd(real_data: Path) -> Path:
    return real_data / "waymo_womd"


def _only_trace(path: Path) -> LabelTrace:
    traces = list(read_traces(path))
    assert len(traces) == 1
    return traces[0]


@pytest.mark.parametrize(
    ("name", "scenario_id", "n_tracks", "classes"),
    [
        (ONE_SCENARIO, "637f20cafde22ff8", 83, {"vehicle": 70, "pedestrian": 10, "cyclist": 3}),
        (SCENARIO_INPUT, "ee519cf571686d19", 257, {"vehicle": 189, "pedestrian": 68}),
    ],
)
def test_trace_counts(womd: Path, name: str, scenario_id: str, n_tracks: int, classes: dict[str, int]) -> None:
    trace = _only_trace(womd / name)
    assert (trace.name, trace.n_objects, trace.n_frames) == (scenario_id, n_tracks, 91)
    assert Counter(trace.objects.category.tolist()) == classes
    assert trace.frame_time[0] == 0.0 and trace.duration == pytest.approx(9.0, abs=0.05)
    assert np.allclose(np.diff(trace.frame_time), 0.1, atol=1e-3)
    assert trace.attributes["scenario_id"] == scenario_id and trace.attributes["current_time_index"] == 10
    assert trace.source is not None and trace.source.format == FORMAT
    assert trace.map_source is not None and trace.map_source.key == scenario_id


@pytest.mark.parametrize("name", [ONE_SCENARIO, SCENARIO_INPUT])
def test_states_follow_valid_flags_and_ego_is_the_sdc(womd: Path, name: str) -> None:
    trace = _only_trace(womd / name)
    ((_, scenario),) = read_scenarios(womd / name)
    assert trace.ego == str(scenario.tracks[scenario.sdc_track_index].id)
    assert len(trace.states) == sum(state.valid for track in scenario.tracks for state in track.states)
    first = scenario.tracks[0]
    step = next(k for k, state in enumerate(first.states) if state.valid)
    row = np.flatnonzero((trace.states.object == 0) & (trace.states.frame == step))[0]
    assert trace.states.x[row] == first.states[step].center_x
    assert trace.states.vy[row] == pytest.approx(first.states[step].velocity_y)


def test_objects_of_interest_and_tracks_to_predict(womd: Path) -> None:
    trace = _only_trace(womd / SCENARIO_INPUT)
    assert trace.attributes["objects_of_interest"] == "625 2694"
    assert trace.attributes["tracks_to_predict"] == "625 2694 2677 635"


@pytest.mark.parametrize("name", [ONE_SCENARIO, SCENARIO_INPUT])
def test_vehicle_headings_agree_with_motion(womd: Path, name: str) -> None:
    trace = _only_trace(womd / name)
    error = heading_motion_error(trace.states, trace.frame_time)
    vehicle = trace.objects.category[trace.states.object] == "vehicle"
    moving = vehicle & ~np.isnan(error)
    assert moving.sum() > 300
    assert np.mean(error[moving] < np.radians(30)) >= 0.9


@pytest.mark.parametrize("name", [ONE_SCENARIO, SCENARIO_INPUT])
def test_moving_vehicles_lie_in_lanes(womd: Path, name: str) -> None:
    trace = _only_trace(womd / name)
    road_map = read_map(womd / name)
    moving = (trace.objects.category[trace.states.object] == "vehicle") & (trace.states.speed() > 2.0)
    inside = road_map.contains("lane", trace.states.x[moving], trace.states.y[moving])
    assert inside.mean() >= 0.9


def test_signal_states(womd: Path) -> None:
    ((_, scenario),) = read_scenarios(womd / ONE_SCENARIO)
    assert len(scenario.dynamic_map_states) == 91
    lanes = {lane.id for lane in read_map(womd / ONE_SCENARIO).lanes}
    signals = scenario.dynamic_map_states[0].lane_states
    assert len(signals) == 12
    assert {str(signal.lane) for signal in signals} <= lanes


def test_map_of_one_scenario(womd: Path) -> None:
    ((_, scenario),) = read_scenarios(womd / ONE_SCENARIO)
    kinds = Counter(feature.WhichOneof("feature_data") for feature in scenario.map_features)
    assert kinds == {"lane": 199, "road_line": 59, "road_edge": 28, "stop_sign": 8, "crosswalk": 4, "speed_bump": 3}
    road_map = read_map(womd / ONE_SCENARIO)
    assert isinstance(road_map, RoadMap) and road_map.name == "637f20cafde22ff8"
    # lane 529 has a one-point polyline and is left out
    assert len(road_map.lanes) == 198 and "529" not in road_map.lane_index
    assert (len(road_map.crosswalks), len(road_map.curbs)) == (4, 28)
    assert sum(lane.kind == "bike" for lane in road_map.lanes) == 1
    # intersection lanes: the 37 that cross another lane on the same level away from their ends (the
    # signalled junction, two driveways, a side junction; checked on a plot) and the 2 signalled right turns
    assert sum(lane.is_intersection for lane in road_map.lanes) == 39
    assert sum(len(area.lanes) for area in road_map.intersections) == 39
    assert sum(len(area.lanes) for area in road_map.roads) == 198 - 39
    assert {round(lane.speed_limit / MPH_TO_MPS) for lane in road_map.lanes if lane.speed_limit} == {10, 15, 40, 45}


def test_lane_topology_and_width(womd: Path) -> None:
    road_map = read_map(womd / ONE_SCENARIO)
    lane = road_map.lanes[road_map.lane_index["172"]]
    assert lane.predecessors == ("170", "162") and lane.successors == ("191", "190")
    assert lane.polygon.area == pytest.approx(2 * 1.8 * _length(lane.centreline), rel=0.02)
    ((_, scenario),) = read_scenarios(womd / ONE_SCENARIO)
    signalled = {str(state.lane) for step in scenario.dynamic_map_states for state in step.lane_states}
    assert len(signalled) == 12
    assert all(road_map.lanes[road_map.lane_index[i]].is_intersection for i in signalled)
    signal_lane = road_map.lanes[road_map.lane_index["431"]]
    assert signal_lane.successors == ("454",)
    widths = [lane.polygon.area / _length(lane.centreline) for lane in road_map.lanes]
    assert 2.0 - 1e-6 <= min(widths) and max(widths) <= 6.0 + 1e-6
    with_neighbour = [lane for lane in road_map.lanes if lane.left is not None]
    assert with_neighbour and all(lane.left.same_direction for lane in with_neighbour)


def _length(line: np.ndarray) -> float:
    return float(np.hypot(*np.diff(line, axis=0).T).sum())


def test_registry_reads_the_map_of_a_trace(womd: Path) -> None:
    path = womd / SCENARIO_INPUT
    assert detect_format(path) == FORMAT
    road_map = registry_read_map(_only_trace(path).map_source)
    assert road_map.name == "ee519cf571686d19" and len(road_map.lanes) == 114


def test_several_scenarios_in_one_file(womd: Path, tmp_path: Path) -> None:
    path = write_tfrecord(
        tmp_path / "two.tfrecord", [*read_records(womd / ONE_SCENARIO), *read_records(womd / SCENARIO_INPUT)]
    )
    assert [trace.name for trace in read_traces(path)] == ["637f20cafde22ff8", "ee519cf571686d19"]
    assert read_map(path).name == "637f20cafde22ff8"
    assert len(read_map(path, "ee519cf571686d19").lanes) == 114
    with pytest.raises(UserError, match="holds no scenario 'nope'"):
        read_map(path, "nope")


@pytest.mark.parametrize(
    ("payload", "message"),
    [
        (b"\xff\xff\xff", "not a Waymo Scenario record"),
        (b"", "not a Waymo Scenario record: it has no scenario_id"),
    ],
)
def test_records_that_are_not_scenarios(tmp_path: Path, payload: bytes, message: str) -> None:
    path = write_tfrecord(tmp_path / "bad.tfrecord", [payload])
    with pytest.raises(UserError) as caught:
        list(read_traces(path))
    assert message in caught.value.one_line() and f"{path}: record 1" in caught.value.one_line()


def test_truncated_real_file(womd: Path, tmp_path: Path) -> None:
    path = tmp_path / "cut.tfrecord"
    path.write_bytes((womd / ONE_SCENARIO).read_bytes()[:100_000])
    with pytest.raises(UserError) as caught:
        list(read_traces(path))
    assert str(path) in caught.value.one_line() and "truncated record data at byte 12" in caught.value.one_line()


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="no such file"):
        read_map(tmp_path / "absent.tfrecord")


def test_parquet_round_trip(womd: Path, tmp_path: Path) -> None:
    try:
        from scenegrep.readers.trace_parquet import read_trace
        from scenegrep.writers.trace_parquet import write_trace_parquet
    except ImportError as exc:
        pytest.skip(f"the Parquet trace modules do not import: {exc}")
    trace = _only_trace(womd / SCENARIO_INPUT)
    back = read_trace(write_trace_parquet(trace, tmp_path / "trace.parquet"))
    assert back.equals(trace)
