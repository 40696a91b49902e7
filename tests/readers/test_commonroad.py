"""The CommonRoad scenario reader, on the NGSIM scenarios in ../shared/real_data and on small
hand-written scenarios for the cases those files do not exercise.

The expected counts below were taken independently of the reader, with grep and regular
expressions over the XML text (planning problems excluded): e.g. US101-3_3 has 12
``<obstacle id=`` elements with 12 initial states and 372 trajectory states at time steps
0..31, and 12 top-level ``<lanelet id=`` elements (plus one ``<lanelet ref=`` in its
planning problem's goal, which is not a lanelet).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from scenegrep import readers
from scenegrep.errors import UserError
from scenegrep.model import LaneNeighbour, MapSource, TraceSource
from scenegrep.model.geometry import heading_from_yaw
from scenegrep.model.kinematics import finite_difference_velocity, heading_motion_error
from scenegrep.readers import commonroad

US101_3 = "USA_US101-3_3_T-1"
US101_4 = "USA_US101-4_1_T-1"
LANKER = "USA_Lanker-1_1_T-1"
PEACH = "USA_Peach-4_8_T-1"

EXPECTED = {
    # name: (version, obstacles, frames, states, lanelets)
    US101_3: ("2018b", 12, 32, 384, 12),
    US101_4: ("2020a", 22, 101, 1271, 12),
    LANKER: ("2018b", 24, 41, 938, 91),
    PEACH: ("2020a", 9, 61, 368, 79),
}

real = pytest.mark.real_data


def _file(real_data: Path, name: str) -> Path:
    return real_data / "commonroad_ngsim" / f"{name}.xml"


# ---------------------------------------------------------------------- real data
@real
@pytest.mark.parametrize("name", EXPECTED)
def test_counts_and_frames(real_data: Path, name: str) -> None:
    version, n_objects, n_frames, n_states, n_lanes = EXPECTED[name]
    path = _file(real_data, name)
    trace = commonroad.read_trace(path)
    assert trace.name == name
    assert trace.attributes["commonroad_version"] == version
    assert trace.attributes["benchmark_id"] == name
    assert (trace.n_objects, trace.n_frames, len(trace.states)) == (n_objects, n_frames, n_states)
    assert set(trace.objects.category.tolist()) == {"car"}
    np.testing.assert_array_equal(trace.frame_index, np.arange(n_frames))
    np.testing.assert_allclose(np.diff(trace.frame_time), 0.1)
    assert trace.ego is None
    assert trace.source == TraceSource(str(path), "commonroad")
    assert trace.map_source == MapSource(str(path), "commonroad")
    assert len(commonroad.read_map(path).lanes) == n_lanes


@real
def test_us101_3_trace(real_data: Path) -> None:
    trace = commonroad.read_trace(_file(real_data, US101_3))
    assert "lane_change" in trace.attributes["tags"].split()
    assert trace.attributes["planning_problems"] == "396"
    assert "396" not in trace.objects.id.tolist()


@real
def test_us101_3_neighbours_follow_the_xml(real_data: Path) -> None:
    path = _file(real_data, US101_3)
    road_map = commonroad.read_map(path)
    lanes = {lane.id: lane for lane in road_map.lanes}
    for lanelet in ET.parse(path).getroot().findall("lanelet"):
        lane = lanes[lanelet.get("id")]
        for tag, side in (("adjacentLeft", lane.left), ("adjacentRight", lane.right)):
            element = lanelet.find(tag)
            expected = (
                None if element is None else LaneNeighbour(element.get("ref"), element.get("drivingDir") == "same")
            )
            assert side == expected, (lane.id, tag)
        assert lane.successors == tuple(s.get("ref") for s in lanelet.findall("successor"))
        assert lane.predecessors == tuple(p.get("ref") for p in lanelet.findall("predecessor"))
    assert sum(lane.left is not None for lane in road_map.lanes) == 9
    assert sum(lane.right is not None for lane in road_map.lanes) == 9
    assert not any(lane.is_intersection for lane in road_map.lanes)
    assert road_map.intersections == ()


@real
def test_peach_intersection_and_speed_limits(real_data: Path) -> None:
    path = _file(real_data, PEACH)
    trace = commonroad.read_trace(path)
    assert "turn_left" in trace.attributes["tags"].split()
    assert trace.attributes["geo_name_id"] == 4179868
    road_map = commonroad.read_map(path)
    assert road_map.name == PEACH
    # The 16 lanelets the <intersection> names plus those inside the hull of its stop lines: one junction
    # area of 38 lanes (checked on a plot: the orange area covers the crossing and nothing else).
    assert sum(lane.is_intersection for lane in road_map.lanes) == 38
    assert len(road_map.intersections) == 1
    # 79 virtual R2-1 signs, one per lanelet: 41 show 11.176 m/s (25 mph), 38 show 15.6464 m/s (35 mph).
    limits = [lane.speed_limit for lane in road_map.lanes]
    assert (limits.count(11.176), limits.count(15.6464)) == (41, 38)


@real
def test_lanker_speed_limits_from_lanelets(real_data: Path) -> None:
    limits = [lane.speed_limit for lane in commonroad.read_map(_file(real_data, LANKER)).lanes]
    assert (limits.count(11.176), limits.count(13.4112)) == (17, 74)


@real
@pytest.mark.parametrize("name", EXPECTED)
def test_headings_velocities_and_lanes_are_consistent(real_data: Path, name: str) -> None:
    path = _file(real_data, name)
    trace = commonroad.read_trace(path)
    error = heading_motion_error(trace.states, trace.frame_time)
    moving = error[~np.isnan(error)]
    assert len(moving) > 0.5 * len(trace.states)
    assert np.mean(moving < np.radians(30)) >= 0.9
    vx, vy = finite_difference_velocity(trace.states, trace.frame_time)
    assert np.nanmedian(np.abs(np.hypot(vx, vy) - trace.states.speed())) < 0.5
    points, _ = commonroad.read_map(path).lanes_containing(trace.states.x, trace.states.y)
    assert len(np.unique(points)) >= 0.9 * len(trace.states)


@real
def test_registry_detects_and_reads_trace_and_map(real_data: Path) -> None:
    path = _file(real_data, US101_3)
    assert readers.detect_format(path) == "commonroad"
    trace = readers.read_trace(path)
    assert trace.equals(commonroad.read_trace(path))
    assert len(readers.read_map(trace.map_source).lanes) == 12


@real
def test_parquet_round_trip(real_data: Path, tmp_path: Path) -> None:
    try:
        from scenegrep.readers.trace_parquet import read_trace
        from scenegrep.writers.trace_parquet import write_trace_parquet
    except Exception as exc:  # another module may be mid-edit; this test only needs them to import
        pytest.skip(f"Parquet trace modules do not import: {exc}")
    trace = commonroad.read_trace(_file(real_data, PEACH))
    assert read_trace(write_trace_parquet(trace, tmp_path / "peach.parquet")).equals(trace)


@real
def test_truncated_file_is_a_located_user_error(real_data: Path, tmp_path: Path) -> None:
    data = _file(real_data, US101_3).read_bytes()
    path = tmp_path / "truncated.xml"
    path.write_bytes(data[: len(data) // 2])
    for read in (commonroad.read_trace, commonroad.read_map):
        with pytest.raises(UserError) as caught:
            read(path)
        location = caught.value.location
        assert location is not None and location.line is not None and location.column is not None
        assert caught.value.one_line().startswith(f"{path}:{location.line}:{location.column}: malformed XML: ")


# ---------------------------------------------------------------------- hand-written scenarios
LANELET = """  <lanelet id="5">
    <leftBound><point><x>0</x><y>2</y></point><point><x>20</x><y>2</y></point></leftBound>
    <rightBound><point><x>0</x><y>-2</y></point><point><x>10</x><y>-2</y></point><point><x>20</x><y>-2</y></point></rightBound>
  </lanelet>"""


def _scenario(tmp_path: Path, body: str, root: str = "commonRoad", version: str = "2020a") -> Path:
    path = tmp_path / "scenario.xml"
    path.write_text(
        f'<?xml version="1.0"?>\n<{root} benchmarkID="TEST-1" commonRoadVersion="{version}" '
        f'timeStepSize="0.5">\n{body}\n</{root}>\n'
    )
    return path


def _state(tag: str, step: int, x: float, yaw: float, velocity: str = "<exact>4</exact>") -> str:
    return (
        f"<{tag}><position><point><x>{x}</x><y>0</y></point></position>"
        f"<orientation><exact>{yaw}</exact></orientation><time><exact>{step}</exact></time>"
        f"<velocity>{velocity}</velocity></{tag}>"
    )


def test_static_obstacles_are_seen_in_every_frame(tmp_path: Path) -> None:
    body = (
        '<staticObstacle id="1"><type>parkedVehicle</type><shape><circle><radius>1.5</radius></circle></shape>'
        + _state("initialState", 0, 3.0, 0.0, "<exact>0</exact>")
        + "</staticObstacle>\n"
        '<dynamicObstacle id="2"><type>car</type><shape><rectangle><length>4.5</length><width>2</width></rectangle>'
        "</shape>"
        + _state("initialState", 2, 0.0, math.pi / 2)
        + "<trajectory>"
        + _state("state", 3, 1.0, math.pi / 2, "<intervalStart>4</intervalStart><intervalEnd>6</intervalEnd>")
        + _state("state", 4, 2.0, math.pi / 2)
        + "</trajectory></dynamicObstacle>\n"
        '<planningProblem id="9">' + _state("initialState", 0, 0.0, 0.0) + "</planningProblem>"
    )
    trace = commonroad.read_trace(_scenario(tmp_path, body))
    np.testing.assert_array_equal(trace.frame_index, [0, 1, 2, 3, 4])
    np.testing.assert_allclose(trace.frame_time, [0.0, 0.5, 1.0, 1.5, 2.0])
    assert trace.objects.id.tolist() == ["1", "2"]
    assert trace.objects.category.tolist() == ["parkedVehicle", "car"]
    assert [a["role"] for a in trace.objects.attributes] == ["static", "dynamic"]
    np.testing.assert_array_equal(trace.observed_frames(), [5, 3])
    np.testing.assert_allclose(trace.dense("x")[:, 0], 3.0)
    np.testing.assert_allclose(trace.dense("length")[0], [3.0, np.nan])
    dynamic = trace.states.object == 1
    np.testing.assert_allclose(trace.states.heading[dynamic], heading_from_yaw(math.pi / 2))
    np.testing.assert_allclose(trace.states.vy[dynamic], [4.0, 5.0, 4.0])
    np.testing.assert_allclose(trace.states.vx[dynamic], 0.0, atol=1e-12)
    assert trace.attributes["planning_problems"] == "9"


def test_2018b_static_obstacle_and_missing_velocity(tmp_path: Path) -> None:
    body = (
        '<obstacle id="7"><role>static</role><type>parkedVehicle</type>'
        "<shape><rectangle><length>4</length><width>2</width></rectangle></shape>"
        "<initialState><position><point><x>1</x><y>2</y></point></position>"
        "<orientation><exact>0</exact></orientation><time><exact>3</exact></time></initialState></obstacle>"
    )
    trace = commonroad.read_trace(_scenario(tmp_path, body, version="2018b"))
    assert (trace.n_frames, trace.n_objects, trace.frame_index.tolist()) == (1, 1, [3])
    assert np.isnan(trace.states.vx).all() and np.isnan(trace.states.vy).all()
    assert trace.attributes["tags"] == ""


def test_hand_written_lanelet(tmp_path: Path) -> None:
    road_map = commonroad.read_map(_scenario(tmp_path, LANELET))
    (lane,) = road_map.lanes
    assert lane.id == "5" and lane.kind == "vehicle" and lane.speed_limit is None
    assert lane.polygon.area == pytest.approx(80.0)
    np.testing.assert_allclose(lane.centreline, [[0, 0], [10, 0], [20, 0]])


def test_wrong_root_is_a_user_error(tmp_path: Path) -> None:
    path = _scenario(tmp_path, LANELET, root="OpenSCENARIO")
    with pytest.raises(UserError, match="root element is <OpenSCENARIO>") as caught:
        commonroad.read_map(path)
    assert caught.value.one_line().startswith(f"{path}:2:1: ")


def test_lanelet_without_left_bound_names_it(tmp_path: Path) -> None:
    body = '  <lanelet id="8">\n    <rightBound><point><x>0</x><y>0</y></point></rightBound>\n  </lanelet>'
    with pytest.raises(UserError) as caught:
        commonroad.read_map(_scenario(tmp_path, body))
    assert caught.value.one_line().endswith("scenario.xml:3:3: <lanelet> 8 has no <leftBound>")


def test_state_without_position_names_the_obstacle(tmp_path: Path) -> None:
    body = (
        '<dynamicObstacle id="4"><type>car</type>\n'
        "<initialState><time><exact>0</exact></time></initialState></dynamicObstacle>"
    )
    with pytest.raises(UserError) as caught:
        commonroad.read_trace(_scenario(tmp_path, body))
    assert caught.value.one_line().endswith("scenario.xml:4:1: <dynamicObstacle> 4 has no <position>")


_CAR = "<type>car</type>"
_POINT = "<position><point><x>0</x><y>0</y></point></position>"
_MINIMAL = (
    f'<dynamicObstacle id="4">{_CAR}<initialState>{_POINT}<time><exact>0</exact></time></initialState>'
    "</dynamicObstacle>"
)


@pytest.mark.parametrize(
    "body, message",
    [
        (_MINIMAL + _MINIMAL, "obstacle id 4 is used twice"),
        (
            f'<dynamicObstacle id="4">{_CAR}<initialState>{_POINT}<time><intervalStart>0</intervalStart>'
            "<intervalEnd>1</intervalEnd></time></initialState></dynamicObstacle>",
            "<dynamicObstacle> 4: the time step 0.5 is not an integer",
        ),
        (
            f'<dynamicObstacle id="4">{_CAR}<initialState><position><point><x>east</x><y>0</y></point></position>'
            "<time><exact>0</exact></time></initialState></dynamicObstacle>",
            "<dynamicObstacle> 4: <x> is not a number: 'east'",
        ),
        (
            f'<obstacle id="4"><role>moving</role>{_CAR}</obstacle>',
            "<obstacle> 4: <role> must be dynamic or static, found 'moving'",
        ),
    ],
)
def test_bad_obstacles_are_located_user_errors(tmp_path: Path, body: str, message: str) -> None:
    path = _scenario(tmp_path, body)
    with pytest.raises(UserError) as caught:
        commonroad.read_trace(path)
    assert caught.value.one_line().startswith(f"{path}:3:")
    assert caught.value.one_line().endswith(message)


def test_missing_file_is_a_user_error(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="no such file"):
        commonroad.read_trace(tmp_path / "absent.xml")
