"""Kinematics in queries against references written here.

Property tests (hypothesis) on random tracks: the speed, velocity and acceleration the engine reads
(``ego.speed``, ``ego.velocity``, ``ego.acceleration``) and the velocity a reader estimates from
positions equal finite differences computed here by brute force, one track at a time; on random
frames, ``RelativeSpeed(X, Y)`` equals |vX - vY| and ``apparent heading of X from Y`` equals Scenic
3.1.1's ``apparentHeadingAtPoint`` rewritten in plain Python (and Scenic's own function).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scenic.core.geometry import apparentHeadingAtPoint

from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.model.kinematics import finite_difference_velocity
from scenegrep.model.layers import UnknownLayers
from scenegrep.scenario import ScenarioOptions, compile_scenario
from scenegrep.readers.av2_forecasting import read_trace
from scenegrep.readers.av2_sensor import read_trace as read_sensor_log
from scenegrep.scene import SceneOptions, compile_scene
from scenegrep.scene.evaluate import Evaluator, Rows
from scenegrep.scene.geometry import geometry_of
from scenegrep.scene.match import labels_of
from tests.scene.frames import AV2, HEADER, MAP, all_driving, av2_ego_velocity, drive_stop_go, matches, trace_of

MAX_GAP_S = 1.0
"""Neighbouring states of a track farther apart than this (s) are not differenced (the engine's rule)."""

FREE = "new Object in everywhere, facing Range(0, 360) deg, with requireVisible False, with allowCollisions True"


# ---------------------------------------------------------------------------- references
def brute_derivative(times: list[float], values: list[float]) -> list[float]:
    """d value / dt at each sample of one track (times increasing): central difference, one-sided at
    the ends and next to gaps longer than MAX_GAP_S, NaN for a sample with no neighbour."""
    out = []
    for i in range(len(times)):
        prev = i - 1 if i > 0 and times[i] - times[i - 1] <= MAX_GAP_S else i
        nxt = i + 1 if i + 1 < len(times) and times[i + 1] - times[i] <= MAX_GAP_S else i
        out.append(math.nan if prev == nxt else (values[nxt] - values[prev]) / (times[nxt] - times[prev]))
    return out


def per_track(trace: LabelTrace, column: np.ndarray) -> np.ndarray:
    """``brute_derivative`` of a per-state column, track by track (a Python loop: the reference)."""
    states = trace.states
    out = np.full(len(states), np.nan)
    for obj in range(trace.n_objects):
        rows = sorted(np.flatnonzero(states.object == obj), key=lambda r: states.frame[r])
        times = [float(trace.frame_time[states.frame[r]]) for r in rows]
        out[rows] = brute_derivative(times, [float(column[r]) for r in rows])
    return out


def scenic_apparent_heading(x: float, y: float, heading: float, bx: float, by: float) -> float:
    """Scenic 3.1.1 ``apparentHeadingAtPoint((x, y), heading, (bx, by))`` (core/geometry.py), in (-π, π]."""
    angle = (heading + math.pi / 2) - math.atan2(y - by, x - bx)
    return math.atan2(math.sin(angle), math.cos(angle))


def angle_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| modulo 2π (radians)."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


# ---------------------------------------------------------------------------- random traces
finite = st.floats(-50, 50, allow_nan=False)


@st.composite
def tracks(draw) -> LabelTrace:
    """A trace of 1-3 objects ('ego' first) over 2-10 frames with random gaps (some over MAX_GAP_S),
    each object present in a random subset of frames; positions and velocities random, a velocity
    sometimes missing (NaN)."""
    n_frames = draw(st.integers(2, 10))
    steps = draw(st.lists(st.sampled_from([0.1, 0.2, 0.5, 0.9, 1.5]), min_size=n_frames - 1, max_size=n_frames - 1))
    times = np.concatenate([[0.0], np.cumsum(steps)])
    n_objects = draw(st.integers(1, 3))
    rows = []
    for obj in range(n_objects):
        present = draw(st.lists(st.booleans(), min_size=n_frames, max_size=n_frames))
        for f in np.flatnonzero(present):
            vx, vy = draw(finite), draw(finite)
            if draw(st.integers(0, 9)) == 0:
                vx = vy = math.nan
            rows.append((f, obj, draw(finite), draw(finite), draw(st.floats(-3, 3)), vx, vy))
    if not rows:
        rows.append((0, 0, 0.0, 0.0, 0.0, 1.0, 1.0))
    f, o, x, y, h, vx, vy = (np.array(column) for column in zip(*rows))
    states = StateTable.build(f.astype(np.int64), o.astype(np.int64), x, y, h, vx=vx, vy=vy)
    ids = ["ego", *(f"o{k}" for k in range(1, n_objects))]
    objects = ObjectTable.build(ids, ["car"] * n_objects)
    return LabelTrace.build("random", np.arange(n_frames), times, objects, states, ego="ego")


@cache
def term_of(program: str, name: str):
    """The numeric term ``name`` is bound to in ``program`` (a scene program; header added), and its
    program objects."""
    query = compile_scene(HEADER + program + f"require {name} > -1e9\n", "k.scenic")
    condition = [r.condition for r in query.program.requirements if not r.implicit][-1]
    return condition.args[1], {o.name: o for o in query.program.objects}


def evaluate(program: str, name: str, trace: LabelTrace, state: dict[str, np.ndarray]) -> np.ndarray:
    """The engine's value of ``name`` at label state rows ``state`` (program object -> rows)."""
    term, objects = term_of(program, name)
    frames = trace.states.frame[next(iter(state.values()))]
    evaluator = Evaluator(Rows(frames, state), labels_of(trace), objects, geometry_of(None))
    return evaluator.value(term)


# ---------------------------------------------------------------------------- properties
@settings(max_examples=150, deadline=None)
@given(tracks())
def test_speed_velocity_and_acceleration_equal_finite_differences(trace):
    states = trace.states
    vx_ref, vy_ref = per_track(trace, states.vx), per_track(trace, states.vy)
    labels = labels_of(trace)
    np.testing.assert_allclose(labels.ax, vx_ref, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(labels.ay, vy_ref, rtol=1e-9, atol=1e-9)
    # the reader's estimate from positions (AV2 sensor logs) is the same difference of positions
    estimated = finite_difference_velocity(states, trace.frame_time)
    np.testing.assert_allclose(estimated[0], per_track(trace, states.x), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(estimated[1], per_track(trace, states.y), rtol=1e-9, atol=1e-9)
    # the language reads them for the ego, in every frame it is in
    ego = np.flatnonzero(states.object == 0)
    program = f"ego = {FREE}\n"
    expected = {
        "ego.speed": np.hypot(states.vx, states.vy)[ego],
        "ego.velocity.x": states.vx[ego],
        "ego.velocity.y": states.vy[ego],
        "ego.acceleration.x": vx_ref[ego],
        "ego.acceleration.y": vy_ref[ego],
    }
    for name, reference in expected.items():
        if np.isnan(reference).any():  # unknown is never a value: a one-line error naming the frame
            first = int(trace.frame_index[states.frame[ego[np.flatnonzero(np.isnan(reference))[0]]]])
            with pytest.raises(UserError, match=rf"has no \w+ for object 'ego' at frame {first}\b"):
                evaluate(program, name, trace, {"ego": ego})
        else:
            np.testing.assert_allclose(evaluate(program, name, trace, {"ego": ego}), reference, rtol=1e-9, atol=1e-9)


pairs = st.lists(st.tuples(*[finite] * 4, st.floats(-7, 7), *[finite] * 4, st.floats(-7, 7)), min_size=1, max_size=12)


def two_objects(frames: list[tuple]) -> LabelTrace:
    """One frame per tuple (x, y, vx, vy, heading of 'ego', then of 'c'), velocities known."""
    rows = []
    for f, (ex, ey, evx, evy, eh, cx, cy, cvx, cvy, ch) in enumerate(frames):
        rows += [(f, 0, ex, ey, eh, evx, evy), (f, 1, cx, cy, ch, cvx, cvy)]
    f, o, x, y, h, vx, vy = (np.array(column) for column in zip(*rows))
    states = StateTable.build(f.astype(np.int64), o.astype(np.int64), x, y, h, vx=vx, vy=vy)
    objects = ObjectTable.build(["ego", "c"], ["car", "car"])
    n = len(frames)
    return LabelTrace.build("pairs", np.arange(n), np.arange(n, dtype=float), objects, states, ego="ego")


@settings(max_examples=150, deadline=None)
@given(pairs)
def test_relative_speed_and_apparent_heading_equal_scenic_definitions(frames):
    trace = two_objects(frames)
    rows = {"ego": np.arange(0, 2 * len(frames), 2), "c": np.arange(1, 2 * len(frames), 2)}
    program = f"ego = {FREE}\nc = {FREE}\n"
    relative = [math.hypot(cvx - evx, cvy - evy) for _, _, evx, evy, _, _, _, cvx, cvy, _ in frames]
    for name in ("RelativeSpeed(c)", "RelativeSpeed(c, ego)"):
        np.testing.assert_allclose(evaluate(program, name, trace, rows), relative, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(evaluate(program, "RelativeSpeed(ego, c)", trace, rows), relative, atol=1e-9)
    far = [(ex, ey, cx, cy) for ex, ey, _, _, _, cx, cy, _, _, _ in frames if math.hypot(cx - ex, cy - ey) > 1e-6]
    if len(far) < len(frames):
        return  # coincident points: the bearing is undefined (Scenic's atan2(0, 0) = 0)
    apparent = [scenic_apparent_heading(cx, cy, ch, ex, ey) for ex, ey, _, _, _, cx, cy, _, _, ch in frames]
    scenic = [apparentHeadingAtPoint((cx, cy), ch, (ex, ey)) for ex, ey, _, _, _, cx, cy, _, _, ch in frames]
    assert np.max(angle_gap(apparent, scenic)) < 1e-12
    for name in ("apparent heading of c", "apparent heading of c from ego"):
        assert np.max(angle_gap(evaluate(program, name, trace, rows), apparent)) < 1e-9


# ---------------------------------------------------------------------------- scene queries
def moving(x: float, y: float, vy: float, vx: float = 0.0) -> tuple:
    """A northbound 4.5 x 2 m car at (x, y) with velocity (vx, vy) m/s."""
    return ("Car", x, y, 0.0, 4.5, 2.0, vx, vy)


# the ego drives at 10 m/s; c, 10 m ahead, brakes from 10 to 4 m/s (frames 1 s apart)
BRAKING = [{"ego": moving(1.75, 20, 10), "c": moving(1.75, 34.5, vy)} for vy in (10.0, 10.0, 7.0, 4.0, 4.0)]


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        # c's acceleration by differences of its velocities: 0, -1.5, -3, -1.5, 0 m/s²
        ("c = new Car ahead of ego by 10\nrequire c.acceleration.y < -1\n", [False, True, True, True, False]),
        ("c = new Car ahead of ego by 10\nrequire c.acceleration.y < -2\n", [False, False, True, False, False]),
        ("c = new Car ahead of ego by 10\nrequire abs(ego.acceleration.y) > 0\n", [False] * 5),
        # |vc - vego| = 0, 0, 3, 6, 6 m/s
        ("c = new Car ahead of ego by 10\nrequire RelativeSpeed(c) > 2\n", [False, False, True, True, True]),
        ("c = new Car ahead of ego by 10\nrequire RelativeSpeed(ego, c) > 4\n", [False, False, False, True, True]),
        ("c = new Car ahead of ego by 10, with speed Range(3, 8)\n", [False, False, True, True, True]),
        ("c = new Car\nrequire abs(apparent heading of c from ego) < 1 deg\n", [True] * 5),
    ],
)
def test_kinematics_in_scene_requirements_and_specifiers(program, expected):
    assert matches("ego = new Car\n" + program, *BRAKING) == expected


def test_apparent_heading_of_a_car_in_the_next_lane():
    """c in the next lane 10 m ahead, both facing north: seen from the ego at a bearing of
    -atan(3.5 / 10.5) (to the right), so c's apparent heading is +0.3217 rad (18.4 deg)."""
    frame = {"ego": moving(1.75, 20, 10), "c": moving(5.25, 30.5, 10)}
    program = "ego = new Car\nc = new Car\nrequire {} < apparent heading of c from ego < {}\n"
    assert math.atan2(3.5, 10.5) == pytest.approx(0.32175, abs=1e-5)
    assert matches(program.format("18.4 deg", "18.5 deg"), frame) == [True]
    assert matches(program.format("-18.5 deg", "-18.4 deg"), frame) == [False]


@pytest.mark.parametrize(
    ("frames", "message"),
    [
        ([{"ego": moving(1.75, 20, 10)}], "trace 'hand' has no acceleration for object 'ego' at frame 0"),
        ([{"ego": ("Car", 1.75, 20, 0.0)}] * 2, "trace 'hand' has no acceleration for object 'ego' at frame 0"),
    ],
)
def test_an_unknown_acceleration_is_an_error_never_true(frames, message):
    """One frame: no neighbour to difference; no velocities: nothing to difference."""
    with pytest.raises(UserError) as caught:
        matches("ego = new Car\nrequire ego.acceleration.y < 1\n", *frames)
    line = caught.value.one_line()
    reason = "accelerations are differences of labeled velocities of the track's neighbouring frames"
    assert line == f"ego.acceleration is unknown: {message} ({reason})"


@pytest.mark.parametrize(
    ("program", "error"),
    [
        ("ego = new Car with acceleration (0, 1)\n", "2:15: the property 'acceleration' cannot be set"),
        ("ego = new Car\nrequire RelativeSpeed(ego.position) > 1\n", "3:23: RelativeSpeed needs scene objects"),
        ("c = new Car\nrequire RelativeSpeed(c) > 1\n", "3:9: RelativeSpeed(X) refers to ego, which is not defined"),
        ("ego = new Car\nrequire RelativeSpeed(ego, ego, ego) > 1\n", "3:9: RelativeSpeed takes 1 or 2 arguments"),
    ],
)
def test_kinematic_errors_are_one_line_at_their_place(program, error):
    for compile_query in (compile_scene, compile_scenario):
        with pytest.raises(UserError) as caught:
            compile_query(HEADER + program, "k.scenic")
        assert caught.value.one_line().startswith(f"k.scenic:{error}")


# ---------------------------------------------------------------------------- scenario guards
OVERTAKEN = [  # the ego at 10 m/s; c 10.5 m ahead speeds up, slows down, moves to the next lane at frame 6
    {"ego": moving(1.75, 20 + 10 * t, 10), "c": moving(1.75 if t < 6 else 5.25, 30.5 + 10 * t, vy)}
    for t, vy in enumerate((10.0, 10.0, 10.0, 14.0, 14.0, 10.0, 10.0, 10.0))
]


@pytest.mark.parametrize(
    ("guard", "expected"),
    [
        ("ego.speed > 5", []),  # always true: Drive ends at once, and no frame is labeled Stop
        ("ego.speed < 5", [0, 1, 2, 3, 4, 5]),  # never true
        ("RelativeSpeed(otherCar) > 2", [0, 5]),  # true at frames 3, 4 (4 m/s)
        ("otherCar.acceleration.y > 1", [4, 5]),  # central differences 0, 0, 2, 2, -2, -2, 0, 0 m/s²
        ("abs(apparent heading of otherCar from ego) > 10 deg", [0, 1, 2, 3]),  # 0, then 0.3217 rad from frame 6
    ],
)
def test_kinematics_in_scenario_guards(guard, expected):
    """Every state is labeled Drive, none Stop: a window of 3 frames matches where the guard that
    would end Drive never holds in it."""
    program = drive_stop_go(guard, "ego = new Car with behavior Go()\notherCar = new Car with behavior Drive()\n")
    query = compile_scenario(program, "guard.scenic")
    options = ScenarioOptions(find_all=True, unknown_layers=UnknownLayers("permissive"))
    result = query.match(all_driving(trace_of(*OVERTAKEN)), 3, MAP, options)
    found = [m.starts.tolist() for m in result.matches if m.correspondence == {"ego": "ego", "otherCar": "c"}]
    assert found == ([expected] if expected else [])


# ---------------------------------------------------------------------------- a real recording
BRAKING_EGO = "ego = new Object in everywhere, facing Range(0, 360) deg\n"


@pytest.fixture(scope="module")
def recording():
    """The AV2 trace and, by hand from its Parquet table, the ego's ('AV') and the focal track's
    time (s, from the timestamps), velocity and acceleration (np.gradient of velocity_x/y: central
    differences, one-sided at the ends) per timestep."""
    if not AV2.exists():
        pytest.skip("../shared/real_data is not here")
    table = pq.read_table(AV2 / f"scenario_{AV2.name}.parquet").to_pandas()
    tracks = {}
    for name, track_id in (("ego", "AV"), ("focal", table.focal_track_id.iloc[0])):
        rows = table[table.track_id == track_id].sort_values("timestep")
        assert rows.timestep.tolist() == list(range(110))
        step_s = (rows.end_timestamp.iloc[0] - rows.start_timestamp.iloc[0]) / (rows.num_timestamps.iloc[0] - 1) / 1e9
        time = rows.timestep.to_numpy() * step_s
        v = np.stack([rows.velocity_x.to_numpy(), rows.velocity_y.to_numpy()], axis=1)
        tracks[name] = (time, v, np.stack([np.gradient(v[:, 0], time), np.gradient(v[:, 1], time)], axis=1))
    trace = read_trace(AV2)
    assert trace.attributes["focal_track_id"] == table.focal_track_id.iloc[0]
    return trace, tracks


def test_acceleration_on_a_real_recording(recording):
    """The ego brakes harder than 1 m/s² (acceleration along its velocity) at timesteps 18-36."""
    trace, tracks = recording
    time, v, a = tracks["ego"]
    assert np.diff(time) == pytest.approx(0.1)
    along = (a * v).sum(axis=1) / np.hypot(v[:, 0], v[:, 1])
    # by hand at timestep 28: v(27) = (0.2237, 3.3001), v(29) = (0.1532, 2.3050) m/s, 0.2 s apart
    assert v[27] == pytest.approx([0.2237, 3.3001], abs=1e-4) and v[29] == pytest.approx([0.1532, 2.3050], abs=1e-4)
    assert along[28] == pytest.approx(-4.99, abs=0.01)
    assert np.flatnonzero(along < -1).tolist() == list(range(18, 37))
    along_velocity = "ego.acceleration.x * ego.velocity.x + ego.acceleration.y * ego.velocity.y"
    program = BRAKING_EGO + f"require {along_velocity} < -ego.speed\n"
    query = compile_scene(HEADER + program, "braking.scenic")
    assert query.match(trace, None, SceneOptions()).frames().tolist() == list(range(18, 37))


def test_relative_speed_on_a_real_recording(recording):
    """|v(focal track) - v(AV)| exceeds 2 m/s except at timesteps 16-19 and 46-57."""
    trace, tracks = recording
    relative = np.hypot(*(tracks["focal"][1] - tracks["ego"][1]).T)
    expected = np.flatnonzero(relative > 2)
    assert np.flatnonzero(relative <= 2).tolist() == [*range(16, 20), *range(46, 58)]
    assert relative[16:20] == pytest.approx([1.87, 1.86, 1.80, 1.97], abs=0.01)
    program = BRAKING_EGO + "c = new Object in everywhere, facing Range(0, 360) deg, with requireVisible False\n"
    query = compile_scene(HEADER + program + "require RelativeSpeed(c) > 2\n", "relative.scenic")
    options = SceneOptions(correspondence={"ego": "AV", "c": trace.attributes["focal_track_id"]})
    assert query.match(trace, None, options).frames().tolist() == expected.tolist()


def test_accelerations_from_estimated_velocities_are_their_differences():
    """AV2 sensor logs record no velocities: the accelerations are the central differences of the
    velocities the reader estimated from positions (here recomputed from the raw ego poses)."""
    log = AV2.parents[1] / "sensor" / "7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
    if not log.exists():
        pytest.skip("../shared/real_data is not here")
    t, vx, vy = av2_ego_velocity(log)
    along = (np.gradient(vx, t) * vx + np.gradient(vy, t) * vy) / np.maximum(np.hypot(vx, vy), 1e-9)
    expected = np.flatnonzero(along < -1.5)  # braking harder than 1.5 m/s² along the motion
    assert 5 <= len(expected) < len(t) / 2
    program = BRAKING_EGO + "require (ego.acceleration.x * ego.velocity.x + ego.acceleration.y * ego.velocity.y)"
    program += " < -1.5 * max(ego.speed, 1e-9)\n"
    query = compile_scene(HEADER + program, "braking.scenic")
    assert query.match(read_sensor_log(log), None, SceneOptions()).frames().tolist() == expected.tolist()
