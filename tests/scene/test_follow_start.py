"""``following roadDirection from X for D`` with X random — a point on a curb, a point of a region
(``intersection``), a vector of ranges — decided by inverting the walk: answers equal a brute-force
reference wherever it is conclusive, and every witness, walked again, reproduces the label.

The map is tests/scene/test_follow.py's (a straight lane, a bend, an exit lane whose centreline
folds back, an intersection lane across the exit) with three curbs: one inside the straight lane,
one across the bend, one along the exit lane over the fold. ``reference_walks`` is Scenic's
``VectorField.followFrom`` written plainly, for many starts and distances at once.

The reference samples X's domain (every 25 cm) and D (25 cm), walks every pair forward (once
per module), and for the walks ending within 1 m of a label moves the start (along the curb, or
by the miss) so that, if the heading sequence stays, the walk ends on the label; it walks those
again. A walk that then reproduces the label (position and heading within the tolerance) is a
conclusive yes; no sampled walk ending within 1 m of the label is taken as a conclusive no; in
between the reference says nothing (only the witness check applies).
"""

from __future__ import annotations

import dataclasses
import math
import re
from functools import cache

import numpy as np
import pytest
import shapely
import shapely.ops
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.scene.follow import walk_end
from scenegrep.scene.follow_inverse import preimages
from scenegrep.scene.follow_regions import _distance_parts
from scenegrep.scene.geometry import MapGeometry
from scenegrep.scene.regions import MapRegion
from tests.scene.frames import HEADER, trace_of
from tests.scene.test_follow import ANYWHERE, FIELD, MAP

CURBS = (
    np.array([[0.5, 5.0], [0.5, 35.0]]),
    np.array([[12.0, 44.0], [17.0, 50.0], [22.0, 58.0]]),
    np.array([[25.0, 59.5], [45.0, 59.5]]),
)
CURB_MAP = dataclasses.replace(MAP, curbs=CURBS)
GEOMETRY = MapGeometry(CURB_MAP)
BOX = (0.5, 3.0, 4.0, 30.0)
"""x_lo, x_hi, y_lo, y_hi of the range-vector start (metres): the straight lane's first 30 m."""
AREA = GEOMETRY.static_geometry(MapRegion("intersection"))
"""The region ``intersection`` as scenegrep models it (the intersection area and lane)."""
KINDS = {
    "curb": ("spot = new OrientedPoint on curb\n", "spot", (-20.0, -8.0)),
    "region": ("spot = new Point on intersection\n", "spot", (6.0, 20.0)),
    "box": ("", f"Range({BOX[0]:g}, {BOX[1]:g}) @ Range({BOX[2]:g}, {BOX[3]:g})", (6.0, 20.0)),
}
"""Per start kind: the lines defining the start, the start expression, the distance range."""
TOL = 1e-4
NEAR_M = 1.0
GRID_M = 0.25


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


def in_domain(kind: str, x: float, y: float) -> bool:
    if kind == "curb":
        return any(shapely.LineString(c).distance(shapely.Point(x, y)) <= 1e-6 for c in CURBS)
    if kind == "region":
        return bool(AREA.covers(shapely.Point(x, y)))
    return BOX[0] <= x <= BOX[1] and BOX[2] <= y <= BOX[3]


@cache
def samples(kind: str):
    """The reference's sampled starts (and, on a curb, its direction there) and distances, and
    every pair's walk end (rows: start-major)."""
    if kind == "curb":
        parts = []
        for line in CURBS:
            for a, b in zip(line[:-1], line[1:]):
                t = np.arange(0.0, 1.0, GRID_M / np.hypot(*(b - a)))
                parts.append(
                    np.column_stack([a + t[:, None] * (b - a), np.tile((b - a) / np.hypot(*(b - a)), (len(t), 1))])
                )
        starts = np.concatenate(parts)
    elif kind == "region":
        x0, y0, x1, y1 = AREA.bounds
        gx, gy = np.meshgrid(np.arange(x0 + GRID_M / 2, x1, GRID_M), np.arange(y0 + GRID_M / 2, y1, GRID_M))
        inside = shapely.covers(AREA, shapely.points(gx.ravel(), gy.ravel()))
        starts = np.column_stack([gx.ravel()[inside], gy.ravel()[inside], np.zeros((inside.sum(), 2))])
    else:
        gx, gy = np.meshgrid(np.arange(BOX[0], BOX[1], GRID_M), np.arange(BOX[2], BOX[3], GRID_M))
        starts = np.column_stack([gx.ravel(), gy.ravel(), np.zeros((gx.size, 2))])
    lo, hi = KINDS[kind][2]
    distances = np.arange(lo, hi + 1e-9, GRID_M)
    x, y = np.repeat(starts[:, 0], len(distances)), np.repeat(starts[:, 1], len(distances))
    d = np.tile(distances, len(starts))
    ex, ey = reference_walks(x, y, d)
    return np.repeat(starts, len(distances), axis=0), d, ex, ey


def reference(kind: str, label: tuple[float, float, float]) -> bool | None:
    """True when a start and distance reproduce the label (found as the module docstring says),
    False when no sampled walk ends within :data:`NEAR_M` of it, else None."""
    starts, d, ex, ey = samples(kind)
    miss = np.stack([label[0] - ex, label[1] - ey], axis=1)
    near = np.flatnonzero(np.max(np.abs(miss), axis=1) <= NEAR_M)
    if not len(near):
        return False
    x, y, along, dist = starts[near, 0], starts[near, 1], starts[near, 2:], d[near].copy()
    if kind == "curb":
        # move s along the curb and D by delta: s e + delta a = miss, a the walk's mean direction
        a = np.stack([ex[near] - x, ey[near] - y], axis=1) / dist[:, None]
        det = along[:, 0] * a[:, 1] - along[:, 1] * a[:, 0]
        ok = np.abs(det) > 1e-9
        safe = np.where(ok, det, 1.0)
        s = (miss[near, 0] * a[:, 1] - miss[near, 1] * a[:, 0]) / safe
        delta = (along[:, 0] * miss[near, 1] - along[:, 1] * miss[near, 0]) / safe
        # along the curb the walk's direction is the curb's: slide the start by the miss
        s, delta = np.where(ok, s, np.einsum("ij,ij->i", miss[near], along)), np.where(ok, delta, 0.0)
        x, y, dist = x + s * along[:, 0], y + s * along[:, 1], dist + delta
        keep = np.ones(len(near), dtype=bool)
    else:
        x, y = x + miss[near, 0], y + miss[near, 1]
        keep = np.ones(len(near), dtype=bool)
    lo, hi = KINDS[kind][2]
    keep &= (dist >= lo) & (dist <= hi)
    keep &= np.array([in_domain(kind, a, b) for a, b in zip(x, y)], dtype=bool)
    if not keep.any():
        return None
    wx, wy = reference_walks(x[keep], y[keep], dist[keep])
    close = (np.abs(wx - label[0]) <= TOL) & (np.abs(wy - label[1]) <= TOL)
    turn = np.abs(np.remainder(heading_at(wx, wy) - label[2] + math.pi, 2 * math.pi) - math.pi)
    return True if np.any(close & (turn <= TOL)) else None


@cache
def query(kind: str):
    lines, start, (lo, hi) = KINDS[kind]
    program = (
        f"ego = new Car at 100 @ 0\n{lines}c = new Car following roadDirection from {start} for Range({lo:g}, {hi:g})"
    )
    return compile_scene(HEADER + program, f"{kind}.scenic")


def match(kind: str, label: tuple[float, float, float]):
    """Whether a car labeled at ``label`` matches, the solver verdicts, and the witness
    (distance, start x, start y) when it does."""
    trace = trace_of({"ego": ("Car", 100.0, 0.0, 0.0), "c": ("Car", *label)})
    options = SceneOptions(Tolerance(TOL, TOL), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    result = query(kind).match(trace, CURB_MAP, options)
    if not result.matched[0]:
        return False, result.matches.notes, None
    values = result.values(0)
    lo, hi = KINDS[kind][2]
    distance = next(v for k, v in values.items() if k.startswith(f"Range({lo:g}, {hi:g})"))
    if kind == "box":
        x = next(v for k, v in values.items() if k.startswith(f"Range({BOX[0]:g},"))
        y = next(v for k, v in values.items() if k.startswith(f"Range({BOX[2]:g},"))
    else:
        x, y = next(v for k, v in values.items() if re.match(r"point (on|in)", k))
    return True, result.matches.notes, (distance, x, y)


def planted(kind: str, index: float, dx: float, dy: float, turn: float) -> tuple[float, float, float]:
    """The end of a sampled walk (``index`` a fraction of the samples), moved and turned."""
    starts, d, ex, ey = samples(kind)
    k = min(int(index * len(d)), len(d) - 1)
    return float(ex[k] + dx), float(ey[k] + dy), float(heading_at(ex[k] + dx, ey[k] + dy)[0] + turn)


def check(kind: str, label: tuple[float, float, float]) -> None:
    """The decision agrees with the reference where it is conclusive, a refutation by the inverted
    walk agrees with it too, and a match's witness, walked again, reproduces the label from X's
    domain (a region or box start the inverse leaves undecided goes to the general solvers, which
    may keep a row they cannot refute)."""
    found, notes, witness = match(kind, label)
    assert sum(notes.values()) <= 1, notes
    if not notes:  # refuted by the heading group, checked before the walk's (scene/match.py)
        assert not found and reference(kind, label) is not True
    if notes["follow-start:unsat"]:
        assert reference(kind, label) is not True, notes
    if found and notes["follow-start:sat"]:
        distance, x, y = witness
        lo, hi = KINDS[kind][2]
        assert lo <= distance <= hi and in_domain(kind, x, y)
        ex, ey = reference_walks(x, y, distance)
        assert max(abs(ex[0] - label[0]), abs(ey[0] - label[1])) <= TOL + 1e-9
    expected = reference(kind, label)
    if expected is not None:
        assert found == expected or (found and not notes["follow-start:sat"] and kind != "curb"), notes


OFFSETS = st.sampled_from([0.0, 0.0, 0.05, -0.3, 1.5, 3.0])


@settings(max_examples=20, deadline=None, derandomize=True)
@given(st.sampled_from(sorted(KINDS)), st.floats(0.0, 1.0), OFFSETS, OFFSETS, st.sampled_from([0.0, 0.0, 0.3]))
def test_random_start_answers_agree_with_a_brute_force_reference(kind, index, dx, dy, turn):
    check(kind, planted(kind, index, dx, dy, turn))


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_planted_walks_match_with_witnesses_and_far_labels_do_not(kind):
    """Three planted walks per kind match (the reference agrees); a label 80 m east of one, beyond
    every walk's reach from the domain, is refuted by the inverted walk (its preimage is empty)."""
    for index in (0.2, 0.5, 0.8):
        label = planted(kind, index, 0.0, 0.0, 0.0)
        assert reference(kind, label) is True
        check(kind, label)
    far = planted(kind, 0.5, 80.0, 0.0, 0.0)
    assert reference(kind, far) is False
    found, notes, _ = match(kind, far)
    assert not found and notes["follow-start:unsat"] == 1


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_a_wide_tolerance_is_not_refuted_by_the_preimage_of_the_label_alone(kind):
    """With a 0.5 m tolerance a label 0.3 m off a planted walk's end matches (that walk ends in its
    box) although the preimage of the label itself may hold no start: the inverted walk refutes
    only boxes at most 1 mm across and leaves this row to the fallback."""
    x, y, heading = planted(kind, 0.5, 0.0, 0.0, 0.0)
    trace = trace_of({"ego": ("Car", 100.0, 0.0, 0.0), "c": ("Car", x + 0.3, y, heading)})
    options = SceneOptions(Tolerance(0.5, 0.5), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    result = query(kind).match(trace, CURB_MAP, options)
    assert result.matched[0], result.matches.notes
    assert result.matches.notes["follow-start:unsat"] == 0


@settings(max_examples=25, deadline=None, derandomize=True)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(-20.0, 28.0))
def test_the_preimage_holds_every_walk_ending_at_its_point(where_x, where_y, distance):
    """Walk forward from a point of the lanes: the preimage of the end holds that start and
    distance."""
    x0, y0, x1, y1 = shapely.union_all(MAP.lane_polygons).bounds
    x, y = x0 + where_x * (x1 - x0), y0 + where_y * (y1 - y0)
    ex, ey = reference_walks(x, y, distance)
    pre = preimages(GEOMETRY, FIELD, ex, ey, np.array([min(distance, -20.0)]), np.array([max(distance, 28.0)]))
    inside = (pre.lo <= distance + 1e-9) & (pre.hi >= distance - 1e-9)
    starts = np.hypot(ex[0] + distance * pre.ax[inside] - x, ey[0] + distance * pre.ay[inside] - y)
    assert np.any(starts <= 1e-6)


def test_distance_parts_cut_at_step_counts_and_zero():
    assert _distance_parts(6.0, 20.0) == [(4, 6.0, 20.0)]
    assert _distance_parts(-20.0, -8.0) == [(4, -20.0, -8.0)]
    assert _distance_parts(-5.0, 27.0) == [(4, -5.0, 0.0), (4, 0.0, 20.0), (5, 20.0, 25.0), (6, 25.0, 27.0)]


@pytest.mark.slow
@pytest.mark.real_data
@pytest.mark.parametrize("scene", ["following_curb", "following_region"])
def test_scenic_samples_from_town01_match_with_witnesses_and_perturbations_do_not(maps_dir, scene):
    """Scenic 3.1.1's own scenes of examples/scenes/following_curb.scenic (a start on a curb) and
    following_region.scenic (a start in an intersection): each matches through the inverted walk
    with a witness whose walk (Scenic's rule) ends at the label; turned by 0.3 rad none matches;
    moved 3 m across its heading no curb scene matches (refuted by the heading group, checked
    early, or by the inverted walk: the preimage of the moved label holds no start on a curb),
    and a region scene that does has a witness reaching the moved label."""
    from pathlib import Path

    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene import load_scene
    from scenegrep.scene.follow import walk_end
    from scenegrep.scene.geometry import geometry_of
    from scenegrep.synth.ground_truth import perturbed
    from scenegrep.synth.scenic_scenes import sample_scenes

    program = Path(__file__).resolve().parents[2] / "examples" / "scenes" / f"{scene}.scenic"
    town = maps_dir / "Town01.xodr"
    trace = sample_scenes(program, 12, map_path=town, seed=5)  # benchmarks/bench_follow.py: 30
    road_map = read_map(town)
    geometry = geometry_of(road_map)
    query = load_scene(program)
    options = SceneOptions(Tolerance(), correspondence={"ego": "ego", "otherCar": "obj1"})
    car = trace.states.object == trace.object_index("obj1")

    def witnesses_reach_labels(result, labels) -> None:
        for frame in np.flatnonzero(result.matched):
            values = result.values(frame)
            distance = next(v for k, v in values.items() if k.startswith("Range"))
            x, y = next(
                v for k, v in values.items() if k.startswith(("point on: on curb", "point on: on intersection"))
            )
            end_x, end_y = walk_end(geometry, FIELD, [x], [y], [distance], None)
            row = np.flatnonzero(car & (labels.states.frame == frame))[0]
            assert abs(end_x[0] - labels.states.x[row]) <= 1e-6 and abs(end_y[0] - labels.states.y[row]) <= 1e-6

    result = query.match(trace, road_map, options)
    assert result.matched.all()
    assert result.matches.notes["follow-start:sat"] == trace.n_frames
    witnesses_reach_labels(result, trace)
    moved_trace = perturbed(trace, "obj1", "lateral", 3.0)
    moved = query.match(moved_trace, road_map, options)
    decided = moved.matches.notes["follow-start:unsat"] + moved.matches.notes["follow-start:sat"]
    assert decided == sum(moved.matches.notes.values())  # the rest refuted by the heading, checked early
    if scene == "following_curb":
        assert not moved.matched.any()
    witnesses_reach_labels(moved, moved_trace)
    turned = query.match(perturbed(trace, "obj1", "heading", 0.3), road_map, options)
    assert not turned.matched.any()


@cache
def town01():
    """Town01's geometry and the union of its lanes and intersection areas (None without ../shared)."""
    from pathlib import Path

    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene.geometry import geometry_of

    path = Path(__file__).resolve().parents[3] / "shared" / "maps" / "Town01.xodr"
    if not path.is_file():
        return None
    geometry = geometry_of(read_map(path))
    road_map = geometry.map
    return geometry, shapely.union_all(list(road_map.lane_polygons) + [a.polygon for a in road_map.intersections])


def town01_walks(seed: int, candidates: int, n: int):
    """Up to ``n`` random Town01 walks for preimage tests: starts among ``candidates`` uniform points
    of the map's bounds that lie within 2 m of its roads, D backwards in [-30, -20] or forwards in
    [10, 20] m (even odds), their ends by the forward walk, and the D range [lo, hi] of each walk's
    preimage: ``(geometry, x, y, distance, ex, ey, lo, hi)``. Skips the test without ../shared."""
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    geometry, roads = found
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = roads.bounds
    points = shapely.points(rng.uniform(x0, x1, candidates), rng.uniform(y0, y1, candidates))
    x, y = shapely.get_coordinates(points[shapely.dwithin(points, roads, 2.0)][:n]).T
    distance = np.where(rng.random(len(x)) < 0.5, rng.uniform(-30, -20, len(x)), rng.uniform(10, 20, len(x)))
    ex, ey = walk_end(geometry, FIELD, x, y, distance, None)
    lo, hi = np.where(distance < 0, -30.0, 10.0), np.where(distance < 0, -20.0, 20.0)
    return geometry, x, y, distance, ex, ey, lo, hi


FOLD_WALK = (383.9042117863049, -325.00586555318347, -26.895910784641323, -30.0, 30.0)
"""A Town01 walk (x, y, D, and the D range inverted) whose second step starts beside a centreline
that folds back (road 14's lane 0: a 0.08 m segment against its neighbour's direction): the
nearest segment changes where the two adjacent segments are equally near, which no vertex line
marks; the preimage missed this start until adjacent segments across a turn of more than 90°
became a competing pair."""


def town01_start_in_preimage(x: float, y: float, distance: float, lo: float, hi: float) -> None:
    """Scenic's walk (the reference) from (x, y) for ``distance`` ends at E; the preimage of E for D
    in [lo, hi] holds (x, y, distance)."""
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    geometry = found[0]
    ex, ey = walk_end(geometry, FIELD, [x], [y], [distance], None)
    pre = preimages(geometry, FIELD, ex, ey, np.array([lo]), np.array([hi]))
    inside = (pre.lo <= distance + 1e-9) & (pre.hi >= distance - 1e-9)
    starts = np.hypot(ex[0] + distance * pre.ax[inside] - x, ey[0] + distance * pre.ay[inside] - y)
    assert np.any(starts <= 1e-6), (x, y, distance)


@pytest.mark.real_data
def test_a_town01_walk_beside_a_folded_centreline_is_in_its_preimage():
    town01_start_in_preimage(*FOLD_WALK)


@pytest.mark.real_data
@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.booleans())
def test_every_town01_walk_is_in_the_preimage_of_its_end(where_x, where_y, where_d, backwards):
    """From random points within 2 m of Town01's lanes and intersections, forwards (10-20 m) and
    backwards (-30 to -20 m, as examples/scenes/following_curb.scenic): the start is in the
    preimage of the end (the invariant a refutation by the inverted walk rests on)."""
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    roads = found[1]
    x0, y0, x1, y1 = roads.bounds
    x, y = x0 + where_x * (x1 - x0), y0 + where_y * (y1 - y0)
    nearest = shapely.ops.nearest_points(roads, shapely.Point(x, y))[0]
    if nearest.distance(shapely.Point(x, y)) > 2.0:
        x, y = nearest.x + 2.0 * where_y - 1.0, nearest.y + 2.0 * where_x - 1.0
    lo, hi = (-30.0, -20.0) if backwards else (10.0, 20.0)
    town01_start_in_preimage(x, y, lo + where_d * (hi - lo), lo, hi)
