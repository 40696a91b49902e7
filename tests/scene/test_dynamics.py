"""Scenic's dynamic properties ``speed``, ``velocity`` and ``angularSpeed`` against labeled velocities.

Synthetic frames check the rules (features within the speed tolerance, properties in requires,
unknown velocities are errors); an Argoverse 2 forecasting recording checks ``with speed`` in a
scene query and ``self.speed`` / ``ego.speed`` in a scenario's guard and require, the expected
frames computed here from the recording's own ``velocity_x`` / ``velocity_y`` columns.
"""

from __future__ import annotations


import numpy as np
import pyarrow.parquet as pq
import pytest

from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.model.layers import UnknownLayers
from scenegrep.readers.av2_forecasting import read_trace
from scenegrep.readers.av2_sensor import read_trace as read_sensor_log
from scenegrep.scenario import ScenarioOptions, compile_scenario
from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.scene.misses import nearest_miss
from scenegrep.writers.trace_json import write_trace_json
from tests.scene.frames import AV2, HEADER, MAP, all_driving, av2_ego_velocity, drive_stop_go, matches, trace_of

MOVING = ("Car", 1.75, 20.0, 0.0, 4.5, 2.0, 0.0, 10.0)  # northbound at 10 m/s
DRIFTING = ("Car", 1.75, 20.0, 0.0, 4.5, 2.0, 6.0, 8.0)  # 10 m/s, but not along the heading
STOPPED = ("Car", 1.75, 20.0, 0.0, 4.5, 2.0, 0.0, 0.0)
UNKNOWN = ("Car", 1.75, 20.0, 0.0)  # no velocity in the data
PERMISSIVE = UnknownLayers("permissive")  # the synthetic map publishes no shoulders


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        ("ego = new Car with speed Range(5, 15)\n", [True, True, False]),
        ("ego = new Car with speed 10\n", [True, True, False]),
        ("ego = new Car with speed 0\n", [False, False, True]),
        ("ego = new Car with velocity (0, 10)\n", [True, False, False]),
        ("ego = new Car with velocity (6, Range(0, 9))\n", [False, True, False]),
        ("ego = new Car\nrequire ego.speed > 5\n", [True, True, False]),
        ("ego = new Car\nrequire ego.velocity.x > 1\n", [False, True, False]),
        ("ego = new Car\nrequire (ego.speed if ego.velocity.y > 9 else 20) > 15\n", [False, True, True]),
    ],
)
def test_speed_and_velocity_are_matched_against_the_labels(program, expected):
    assert matches(program, {"ego": MOVING}, {"ego": DRIFTING}, {"ego": STOPPED}) == expected


def test_the_speed_tolerance_admits_speeds_within_it():
    program = "ego = new Car with speed 10.05\n"
    assert matches(program, {"ego": MOVING}) == [False]
    assert matches(program, {"ego": MOVING}, speed=0.1) == [True]
    assert matches(program, {"ego": MOVING}, position=1.0, heading=1.0) == [False]  # not the other tolerances


def test_a_nearest_miss_names_the_speed_tolerance_that_admits_it():
    query = compile_scene(HEADER + "ego = new Car at (1.75, 20), facing 0 deg, with speed 12.5\n")
    result = query.match(trace_of({"ego": MOVING}), MAP, SceneOptions(unknown_layers=PERMISSIVE))
    miss = nearest_miss(result, np.array([0]))
    assert [(s.name, s.value) for s in miss.needed] == [("speed", pytest.approx(2.5, rel=1e-3))]
    admitted = SceneOptions(miss.tolerance(Tolerance()), unknown_layers=PERMISSIVE)
    assert query.match(trace_of({"ego": MOVING}), MAP, admitted).matched[0]


@pytest.mark.parametrize(
    ("program", "feature"),
    [
        ("ego = new Car with speed Range(13.9, 40)\n", "ego.speed"),
        ("ego = new Car with velocity (0, 10)\n", "ego.velocity"),
        ("ego = new Car\nrequire ego.speed < 100\n", "ego.speed"),
        ("ego = new Car\nother = new Car ahead of ego\nrequire other.velocity.y < 100\n", "other.velocity"),
    ],
)
def test_an_unknown_velocity_is_an_error_never_true(program, feature):
    with pytest.raises(UserError) as caught:
        matches(program, {"ego": UNKNOWN, "c": ("Car", 1.75, 30.0, 0.0)})
    assert caught.value.one_line().startswith(f"{feature} is unknown: trace 'hand' has no ")


def test_angular_speed_is_unknown_in_every_trace():
    with pytest.raises(UserError, match="ego.angularSpeed is unknown: trace 'hand' has no angularSpeed"):
        matches("ego = new Car with angularSpeed 0\n", {"ego": MOVING})


def test_the_cli_reports_an_unknown_speed_in_one_line_and_fails_the_trace(tmp_path, capsys):
    """The lone trace lacks what the query needs: a user error (exit 2) on one line."""
    (tmp_path / "fast.scenic").write_text(HEADER + "ego = new Object at (1.75, 20), with speed Range(13.9, 40)\n")
    write_trace_json(trace_of({"ego": UNKNOWN}), tmp_path / "t.json")
    code = main(["scene", str(tmp_path / "fast.scenic"), str(tmp_path / "t.json")])
    err = capsys.readouterr().err.splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("scenegrep: error: ")
    assert err[0].endswith("t.json: ego.speed is unknown: trace 'hand' has no speed for object 'ego' at frame 0")


def test_the_cli_speed_tolerance(tmp_path, capsys):
    (tmp_path / "fast.scenic").write_text(HEADER + "ego = new Object at (1.75, 20), with speed 10.5\n")
    write_trace_json(trace_of({"ego": MOVING}), tmp_path / "t.json")
    args = ["scene", str(tmp_path / "fast.scenic"), str(tmp_path / "t.json"), "-q"]
    assert main(args) == 1
    assert main([*args, "--tolerance-speed", "0.5"]) == 0
    assert main([*args, "--tolerance-speed", "-1"]) == 2


# ---------------------------------------------------------------------------- a real recording
ANYWHERE = "ego = new Object in everywhere, facing Range(0, 360) deg"


@pytest.fixture(scope="module")
def recording():
    """The AV2 trace and, by hand from its Parquet table, the ego's ('AV') speed per timestep (m/s)."""
    if not AV2.exists():
        pytest.skip("../shared/real_data is not here")
    table = pq.read_table(AV2 / f"scenario_{AV2.name}.parquet").to_pandas()
    ego = table[table.track_id == "AV"].sort_values("timestep")
    assert ego.timestep.tolist() == list(range(110))
    speed = np.hypot(ego.velocity_x.to_numpy(), ego.velocity_y.to_numpy())
    return read_trace(AV2), speed


def test_with_speed_on_a_real_recording(recording):
    trace, speed = recording
    # by hand: the ego decelerates from 7.0 m/s (timestep 16) to 0.12 m/s (timestep 39) and accelerates again
    assert speed[16] == pytest.approx(6.9680, abs=1e-4) and speed[39] == pytest.approx(0.1216, abs=1e-4)
    expected = np.flatnonzero((speed >= 3) & (speed <= 5))
    assert expected.tolist() == [24, 25, 26, 27, *range(58, 69)]
    query = compile_scene(HEADER + ANYWHERE + ", with speed Range(3, 5)\n", "speed.scenic")
    assert query.match(trace, None, SceneOptions()).frames().tolist() == expected.tolist()


def test_speed_in_a_scenario_guard_and_require_on_a_real_recording(recording):
    """Every frame is labeled Drive and none Stop, so a window matches when the ego's speed exceeds
    5 m/s at its first frame (the require: the initial scene) and stays at or above 1 m/s in every
    frame of it (the guard never ends Drive)."""
    program = drive_stop_go("self.speed < 1", f"{ANYWHERE}, with behavior Go()\nrequire ego.speed > 5\n")
    trace, speed = recording
    window = 15
    starts = range(len(speed) - window + 1)
    expected = [s for s in starts if speed[s] > 5 and (speed[s : s + window] >= 1).all()]
    assert expected == [*range(19), *range(69, 96)]  # 19..23 start fast but reach 0.81 m/s at timestep 33
    query = compile_scenario(program, "go.scenic")
    result = query.match(all_driving(trace), window, None, ScenarioOptions(find_all=True))
    assert [(m.correspondence, m.starts.tolist()) for m in result.matches] == [({"ego": "AV"}, expected)]


def test_velocities_a_reader_estimated_from_positions_are_the_speeds():
    """AV2 sensor logs record no velocities; the reader's central differences of positions are
    the speeds queries read (issue 16: estimated where a dataset has none, documented). The ego
    of 7fab2350 brakes from 10 m/s to a stop and drives off again: 3-5 m/s in two stretches."""
    log = AV2.parents[1] / "sensor" / "7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
    if not log.exists():
        pytest.skip("../shared/real_data is not here")
    _, vx, vy = av2_ego_velocity(log)
    speed = np.hypot(vx, vy)
    expected = np.flatnonzero((speed > 3) & (speed < 5))
    assert 5 <= len(expected) <= 40 and speed[0] > 9 and speed.min() < 0.5
    query = compile_scene(HEADER + ANYWHERE + ", with speed Range(3, 5)\n", "speed.scenic")
    found = query.match(read_sensor_log(log), None, SceneOptions(Tolerance(speed=1e-9)))
    assert found.frames().tolist() == expected.tolist()
