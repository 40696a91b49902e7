"""Simulated label traces from the real Scenic: facts checked on runs of seed 000's Fig. 1 program."""

import numpy as np
import pytest

from scenegrep.errors import UserError
from scenegrep.synth.simulate import run_seed, simulate_runs
from tests.synth.conftest import SCENARIOS

pytestmark = pytest.mark.slow

FIG1 = SCENARIOS / "fig1_lane_change.scenic"
HEADER = "model scenic.simulators.newtonian.driving_model\n"


@pytest.fixture(scope="module")
def town06(maps_dir):
    return maps_dir / "Town06.xodr"


@pytest.fixture(scope="module")
def town01(maps_dir):
    return maps_dir / "Town01.xodr"


@pytest.fixture(scope="module")
def fig1(town06, scenic_cache):
    return list(simulate_runs(FIG1, map_path=town06, runs=3, steps=100, seed=0))


def runs_of(labels):
    """The sequence of distinct consecutive values."""
    return [v for k, v in enumerate(labels) if k == 0 or v != labels[k - 1]]


def object_column(trace, object_id, values):
    return np.asarray(values)[trace.states.object == trace.object_index(object_id)]


def test_objects_frames_and_attributes(fig1, town06):
    for run, trace in enumerate(fig1):
        assert trace.name == f"fig1_lane_change-{run:03d}" and trace.ego == "ego"
        assert trace.objects.id.tolist() == ["ego", "otherCar"] and trace.objects.category.tolist() == ["Car", "Car"]
        assert np.array_equal(trace.frame_index, np.arange(100)) and np.allclose(trace.frame_time, np.arange(100) * 0.1)
        assert trace.present().all()
        assert trace.map_source.path == str(town06) and trace.map_source.format == "opendrive"
        a = trace.attributes
        assert (a["program"], a["seed"], a["run"], a["steps"], a["timestep"]) == (
            "fig1_lane_change.scenic",
            0,
            run,
            100,
            0.1,
        )
        assert a["run_seed"] == run_seed(0, run) and a["scenic_version"] == "3.1.1"
        assert a["rejected_simulations"] >= 0 and a["rejected_scenes"] >= 0
        assert np.all(trace.states.length == 4.5) and np.all(trace.states.width == 2)
        assert np.all((trace.states.heading > -np.pi) & (trace.states.heading <= np.pi))


def test_ego_follows_changes_lane_then_follows(fig1):
    """Fig. 1: FollowLane until the stationary car is near, LaneChange, FollowLane; the ego's
    lane id changes while the LaneChange runs, and it ends on another lane than it started."""
    for trace in fig1:
        labels = [sorted(s)[0] for s in object_column(trace, "ego", trace.behaviours.sets())]
        assert runs_of(labels) == ["FollowLane", "LaneChange", "FollowLane"]
        start, end = labels.index("LaneChange"), len(labels) - labels[::-1].index("LaneChange")
        lanes = object_column(trace, "ego", trace.lane_names())
        assert "" not in lanes
        assert lanes[start - 1] != lanes[end]
        assert any(lanes[t] != lanes[t - 1] for t in range(start, end + 1))


def test_other_car_is_stationary(fig1):
    for trace in fig1:
        labels = object_column(trace, "otherCar", trace.behaviours.sets())
        assert all(s == {"Stationary"} for s in labels)
        for column in ("x", "y", "vx", "vy"):
            values = object_column(trace, "otherCar", getattr(trace.states, column))
            assert np.all(values == values[0])
        assert trace.attributes["behaviour_stacks"]["otherCar"] == [[0, []]]


def test_behaviour_stacks_name_the_running_behaviours(fig1):
    stacks = fig1[0].attributes["behaviour_stacks"]["ego"]
    assert [s for _, s in stacks][:3] == [
        ["EgoBehavior", "FollowLaneBehavior"],
        ["EgoBehavior", "LaneChangeBehavior"],
        ["EgoBehavior", "FollowLaneBehavior"],
    ]
    labels = [sorted(s)[0] for s in object_column(fig1[0], "ego", fig1[0].behaviours.sets())]
    assert stacks[1][0] == labels.index("LaneChange")


def test_velocity_is_the_displacement_per_second(fig1):
    """The Newtonian step moves each object by its new velocity times 0.1 s."""
    trace = fig1[0]
    x, y, vx, vy = (trace.dense(c)[:, 0] for c in ("x", "y", "vx", "vy"))
    assert np.allclose(np.diff(x), vx[1:] * 0.1, atol=1e-9) and np.allclose(np.diff(y), vy[1:] * 0.1, atol=1e-9)
    assert np.hypot(vx, vy).max() > 5


def test_same_seed_same_traces_other_seed_other_traces(fig1, town06):
    again = list(simulate_runs(FIG1, map_path=town06, runs=2, steps=100, seed=0))
    assert all(a.equals(b) for a, b in zip(again, fig1))
    other = next(simulate_runs(FIG1, map_path=town06, runs=1, steps=100, seed=1))
    assert not np.array_equal(other.states.x, fig1[0].states.x)
    assert other.attributes["run_seed"] != fig1[0].attributes["run_seed"]


def test_noise_is_applied_per_run(fig1, town06):
    from scenegrep.synth.noise import LabelNoise

    noise = LabelNoise(position=0.5, drop_frames=0.2, seed=3)
    noisy = list(simulate_runs(FIG1, map_path=town06, runs=2, steps=100, seed=0, noise=noise))
    for run, trace in enumerate(noisy):
        assert trace.attributes["noise"] == noise.as_dict() and trace.attributes["noise_stream"] == run
        kept = np.searchsorted(fig1[run].frame_index, trace.frame_index)
        assert 50 < len(kept) < 100
        error = trace.dense("x") - fig1[run].dense("x")[kept]
        assert 0.3 < error.std() < 0.7
    assert not np.array_equal(noisy[0].frame_index, noisy[1].frame_index)


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_error_while_running_is_located_in_the_program(tmp_path, town01, scenic_cache):
    program = write(
        tmp_path,
        "broken.scenic",
        HEADER + "behavior B():\n    take SetThrottleAction(self.nosuch)\nego = new Car with behavior B()\n",
    )
    with pytest.raises(UserError) as caught:
        next(simulate_runs(program, map_path=town01, runs=1, steps=5))
    assert str(caught.value) == f"{program}:3:28: AttributeError: 'Car' object has no attribute 'nosuch'"


def test_program_must_use_the_newtonian_simulator(tmp_path, town01, scenic_cache):
    program = write(tmp_path, "abstract.scenic", "model scenic.domains.driving.model\nego = new Car\n")
    with pytest.raises(UserError, match="must use the Newtonian driving model"):
        next(simulate_runs(program, map_path=town01, runs=1, steps=5))


def test_every_simulation_rejected_is_a_user_error(tmp_path, town01, scenic_cache):
    program = write(
        tmp_path,
        "never.scenic",
        HEADER + "ego = new Car with behavior FollowLaneBehavior()\nrequire always ego.speed < 1\n",
    )
    with pytest.raises(UserError) as caught:
        next(simulate_runs(program, map_path=town01, runs=1, steps=10, max_iterations=3))
    assert str(caught.value) == f"{program}: Scenic rejected all 3 simulations of run 0"
    short = next(simulate_runs(program, map_path=town01, runs=1, steps=3))
    assert short.n_frames == 3 and short.attributes["rejected_simulations"] == 0


def test_names_and_fallback_ids(tmp_path, town01, scenic_cache):
    program = write(
        tmp_path,
        "names.scenic",
        HEADER + "ego = new Car\nnew Car ahead of ego by 5\nnew Car behind ego by 5, with name 'tail'\n"
        "new Car ahead of ego by 20\n",
    )
    trace = next(simulate_runs(program, map_path=town01, runs=1, steps=2))
    assert trace.objects.id.tolist() == ["ego", "obj1", "tail", "obj3"]


@pytest.mark.parametrize(
    "body, message",
    [
        (
            "ego = new Car\nnew Car ahead of ego by 5, with name 'a'\nnew Car behind ego by 5, with name 'a'\n",
            "several objects are named 'a'",
        ),
        ("ego = new Car\nterminate when True\n", "the simulation ended before its first step"),
    ],
)
def test_programs_whose_traces_cannot_be_built(tmp_path, town01, scenic_cache, body, message):
    program = write(tmp_path, "odd.scenic", HEADER + body)
    with pytest.raises(UserError, match=message):
        next(simulate_runs(program, map_path=town01, runs=1, steps=5))
