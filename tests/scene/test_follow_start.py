"""``following roadDirection from spot for D`` with ``spot`` a random point on a curb: exact regions
of (s, D), a witness that reproduces the label, and answers that agree with a dense search.

The map is tests/scene/test_follow.py's (a straight lane, a bend, an exit lane whose centreline
folds back, an intersection lane) with three curbs: one inside the straight lane, one across the
bend, one along the exit lane over the fold. ``reference_walks`` is Scenic's
``VectorField.followFrom`` written plainly, for many starts and distances at once.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.scene.follow_regions import _distance_parts
from scenegrep.scene.geometry import MapGeometry
from tests.scene.frames import HEADER, trace_of
from tests.scene.test_follow import ANYWHERE, FIELD, MAP

CURBS = (
    np.array([[0.5, 5.0], [0.5, 35.0]]),
    np.array([[12.0, 44.0], [17.0, 50.0], [22.0, 58.0]]),
    np.array([[25.0, 59.5], [45.0, 59.5]]),
)
CURB_MAP = dataclasses.replace(MAP, curbs=CURBS)
GEOMETRY = MapGeometry(CURB_MAP)
PROGRAM = (
    "ego = new Car at 100 @ 0\nspot = new OrientedPoint on curb\n"
    "c = new Car following roadDirection from spot for Range({lo}, {hi})"
)
RANGES = [(6.0, 20.0), (-20.0, -8.0), (15.0, 28.0)]
"""Distance ranges tried: four steps either way, and a range across a change of step count."""


def reference_walks(x, y, distance):
    """Scenic's followFrom from each (x[i], y[i]) for distance[i] metres: the ends' x and y."""
    x, y, d = (np.array(a, dtype=float, ndmin=1) for a in np.broadcast_arrays(x, y, distance))
    steps = np.maximum(4, np.ceil(d / 5)).astype(int)
    for k in range(int(steps.max())):
        walking = k < steps
        heading = GEOMETRY.scenic_headings(FIELD, x[walking], y[walking], None)
        x[walking] -= np.sin(heading) * d[walking] / steps[walking]
        y[walking] += np.cos(heading) * d[walking] / steps[walking]
    return x, y


def heading_at(x, y) -> np.ndarray:
    return GEOMETRY.scenic_headings(FIELD, np.atleast_1d(x), np.atleast_1d(y), None)


def curb_point(curb: int, where: float) -> tuple[float, float]:
    """The point a fraction ``where`` of the way along a curb polyline (by length)."""
    line = CURBS[curb]
    lengths = np.hypot(*np.diff(line, axis=0).T)
    arc = where * lengths.sum()
    k = min(int(np.searchsorted(np.cumsum(lengths), arc)), len(lengths) - 1)
    t = (arc - np.concatenate([[0.0], np.cumsum(lengths)])[k]) / lengths[k]
    x, y = line[k] + t * (line[k + 1] - line[k])
    return float(x), float(y)


def match(lo: float, hi: float, label: tuple[float, float, float], tol: float):
    """Whether a car labeled at ``label`` matches, the solver verdicts, and the witness
    (distance, start point) when it does."""
    query = compile_scene(HEADER + PROGRAM.format(lo=lo, hi=hi), "start.scenic")
    trace = trace_of({"ego": ("Car", 100.0, 0.0, 0.0), "c": ("Car", *label)})
    options = SceneOptions(Tolerance(tol, tol), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    result = query.match(trace, CURB_MAP, options)
    if not result.matched[0]:
        return False, result.matches.notes, None
    values = result.values(0)
    distance = next(v for k, v in values.items() if k.startswith("Range"))
    point = next(v for k, v in values.items() if "curb" in k)
    return True, result.matches.notes, (distance, point)


def dense_search(lo: float, hi: float, label, tol: float) -> bool:
    """Whether some start on a grid along every curb (at most 5 cm apart; those within reach of the
    label) and distance (2 cm) reproduces the label."""
    starts = np.array([curb_point(c, w) for c in range(len(CURBS)) for w in np.linspace(0, 1, 600)])
    reach = np.hypot(starts[:, 0] - label[0], starts[:, 1] - label[1]) <= max(-lo, hi) + 2 * tol
    starts = starts[reach]
    distances = np.linspace(lo, hi, int(round((hi - lo) / 0.02)) + 1)
    x, y = np.repeat(starts[:, 0], len(distances)), np.repeat(starts[:, 1], len(distances))
    ex, ey = reference_walks(x, y, np.tile(distances, len(starts)))
    close = (np.abs(ex - label[0]) <= tol) & (np.abs(ey - label[1]) <= tol)
    if not close.any():
        return False
    turn = np.abs(np.remainder(heading_at(ex[close], ey[close]) - label[2] + math.pi, 2 * math.pi) - math.pi)
    return bool(np.any(turn <= tol))


def reproduces(witness, label, tol: float) -> bool:
    distance, (x, y) = witness
    ex, ey = reference_walks(x, y, distance)
    return max(abs(ex[0] - label[0]), abs(ey[0] - label[1])) <= tol + 1e-9


def test_distance_parts_cut_at_step_counts_and_zero():
    assert _distance_parts(6.0, 20.0) == [(4, 6.0, 20.0)]
    assert _distance_parts(-20.0, -8.0) == [(4, -20.0, -8.0)]
    assert _distance_parts(-5.0, 27.0) == [(4, -5.0, 0.0), (4, 0.0, 20.0), (5, 20.0, 25.0), (6, 25.0, 27.0)]


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.integers(0, len(CURBS) - 1), st.floats(0.0, 1.0), st.sampled_from(RANGES), st.floats(0.0, 1.0))
def test_a_planted_walk_from_a_curb_matches_with_a_witness_that_reproduces_it(curb, where, span, share):
    lo, hi = span
    x, y = curb_point(curb, where)
    ex, ey = reference_walks(x, y, lo + share * (hi - lo))
    label = (float(ex[0]), float(ey[0]), float(heading_at(ex, ey)[0]))
    found, notes, witness = match(lo, hi, label, 1e-4)
    assert found
    if notes["follow-start:sat"]:
        assert reproduces(witness, label, 1e-4)
        assert lo <= witness[0] <= hi


@settings(max_examples=3, deadline=None, derandomize=True)
@given(
    st.integers(0, len(CURBS) - 1),
    st.floats(0.0, 1.0),
    st.sampled_from(RANGES[:2]),
    st.floats(0.0, 1.0),
    st.floats(-0.3, 0.3),
    st.floats(-0.3, 0.3),
)
def test_random_start_answers_agree_with_a_dense_search(curb, where, span, share, dx, dy):
    """A perturbed label: a match decided here has a reproducing witness (no false match), and a
    dense search finding a reproducing start and distance means a match (no false miss)."""
    lo, hi = span
    x, y = curb_point(curb, where)
    ex, ey = reference_walks(x, y, lo + share * (hi - lo))
    label = (float(ex[0]) + dx, float(ey[0]) + dy, float(heading_at(ex, ey)[0]))
    tol = 0.05
    found, notes, witness = match(lo, hi, label, tol)
    if found and notes["follow-start:sat"]:
        assert reproduces(witness, label, tol)
    if dense_search(lo, hi, label, tol):
        assert found
    if not found:
        assert notes["follow-start:unsat"]


def test_labels_no_start_can_produce_do_not_match():
    """Turned by 0.3 rad, or moved 3 m across the road direction: no start and distance reproduce
    the label (the dense search agrees), and the query says so itself, without the general solvers."""
    lo, hi = RANGES[0]
    x, y = curb_point(0, 0.4)
    ex, ey = reference_walks(x, y, 12.0)
    heading = float(heading_at(ex, ey)[0])
    assert match(lo, hi, (float(ex[0]), float(ey[0]), heading), 1e-4)[0]
    across = (-math.cos(heading), -math.sin(heading))
    for label in (
        (float(ex[0]), float(ey[0]), heading + 0.3),
        (float(ex[0]) + 3 * across[0], float(ey[0]) + 3 * across[1], heading),
    ):
        assert not dense_search(lo, hi, label, 1e-4)
        assert not match(lo, hi, label, 1e-4)[0]
    moved = (float(ex[0]) + 3 * across[0], float(ey[0]) + 3 * across[1], heading)
    assert match(lo, hi, moved, 1e-4)[1]["follow-start:unsat"] == 1


@pytest.mark.slow
@pytest.mark.real_data
def test_scenic_samples_from_town01_curbs_match_with_witnesses_and_perturbations_do_not(maps_dir):
    """Scenic 3.1.1's own scenes of examples/scenes/following_curb.scenic: each matches through
    this path with a witness whose walk (Scenic's rule) ends at the label; moved 3 m across its
    heading or turned by 0.3 rad, none matches (the moved ones refuted here, exactly)."""
    from pathlib import Path

    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene import load_scene
    from scenegrep.scene.follow import walk_end
    from scenegrep.scene.geometry import geometry_of
    from scenegrep.synth.ground_truth import perturbed
    from scenegrep.synth.scenic_scenes import sample_scenes

    program = Path(__file__).resolve().parents[2] / "examples" / "scenes" / "following_curb.scenic"
    town = maps_dir / "Town01.xodr"
    trace = sample_scenes(program, 12, map_path=town, seed=5)  # benchmarks/bench_follow.py --random-start: 30
    road_map = read_map(town)
    geometry = geometry_of(road_map)
    query = load_scene(program)
    options = SceneOptions(Tolerance(), correspondence={"ego": "ego", "otherCar": "obj1"})
    result = query.match(trace, road_map, options)
    assert result.matched.all()
    assert result.matches.notes["follow-start:sat"] == trace.n_frames
    car = trace.states.object == trace.object_index("obj1")
    for frame in range(trace.n_frames):
        values = result.values(frame)
        distance = values["Range(-30, -20)@7:58"]
        x, y = values["point on: on curb@6:26"]
        end_x, end_y = walk_end(geometry, FIELD, [x], [y], [distance], None)
        row = np.flatnonzero(car & (trace.states.frame == frame))[0]
        assert abs(end_x[0] - trace.states.x[row]) <= 1e-6 and abs(end_y[0] - trace.states.y[row]) <= 1e-6
    moved = query.match(perturbed(trace, "obj1", "lateral", 3.0), road_map, options)
    assert not moved.matched.any()
    assert moved.matches.notes["follow-start:unsat"] == trace.n_frames
    turned = query.match(perturbed(trace, "obj1", "heading", 0.3), road_map, options)
    assert not turned.matched.any()
