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
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scenic.core.geometry import apparentHeadingAtPoint

from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.model.kinematics import finite_difference_velocity
from scenegrep.scene import compile_scene
from scenegrep.scene.evaluate import Evaluator, Rows
from scenegrep.scene.geometry import geometry_of
from scenegrep.scene.match import labels_of
from tests.scene.frames import HEADER

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
