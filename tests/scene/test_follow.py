"""``following roadDirection from X for D``: exact pieces, exact decisions, witnesses, Scenic itself.

The small map here has a straight lane sampled every 2 m, a quarter-circle bend, a lane whose
centreline folds back on itself (as lane sections join in CARLA maps) and an intersection lane
across the exit. ``reference_follow`` is Scenic's ``VectorField.followFrom`` written plainly:
``max(4, ceil(D / 5))`` steps of equal length, each along the field at the current point.

* the pieces hold every walk (here and on Town01 and Town06), also when only the pieces that
  may reach a box are asked for;
* a walk planted in a label matches, and its printed D, walked again, reproduces the label;
* on perturbed labels every match has a reproducing witness, and a dense search over D that
  finds a reproducing value implies a match;
* the ``follow`` operator and a requirement on D (pieces sent to the general solvers) agree;
* Scenic 3.1.1's own samples of examples/ground_truth/following.scenic match, perturbed ones not.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model import Area, Lane, RoadMap
from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.scene.follow_pieces import follow_pieces
from scenegrep.scene.geometry import MapGeometry
from scenegrep.scene.regions import MapField
from tests.scene.frames import HEADER, trace_of

FIELD = MapField("lanes")
PROGRAM = "ego = new Car on road\nc = new Car following roadDirection from ego for Range({lo}, {hi})"


def _lane(name: str, points: list[tuple[float, float]], intersection: bool = False) -> Lane:
    line = np.array(points, dtype=float)
    polygon = shapely.buffer(shapely.LineString(line), 1.75, cap_style="flat")
    return Lane(name, polygon, line, is_intersection=intersection)


def curved_map() -> RoadMap:
    straight = [(1.75, float(y)) for y in range(0, 42, 2)]
    bend = [(21.75 - 20 * math.cos(t), 40 + 20 * math.sin(t)) for t in np.linspace(0, math.pi / 2, 17)]
    exit_lane = [(21.75, 60.0), (40.0, 60.0), (40.3, 60.0), (40.1, 60.0), (70.0, 60.0)]
    crossing = [(50.0, 80.0), (50.0, 40.0)]
    lanes = (
        _lane("a", straight),
        _lane("b", bend),
        _lane("c", exit_lane),
        _lane("x", crossing, intersection=True),
    )
    area = Area("i", shapely.box(48.25, 58.25, 51.75, 61.75), ("x",))
    return RoadMap("curved", lanes, roads=(), intersections=(area,), unknown_layers=frozenset({"shoulder"}))


MAP = curved_map()
ANYWHERE = UnknownLayers("permissive")
"""The map models no shoulders: the cars' default road-or-shoulder constrains nothing here."""
GEOMETRY = MapGeometry(MAP)


def reference_walk(
    x: float, y: float, distance, geometry: MapGeometry = GEOMETRY
) -> Iterator[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Scenic's followFrom step by step: equal Euler steps along the road direction at the current
    point, one walk per distance (``distance`` one number or an array). Yields, before each step,
    the walks' positions and which of them take it; last, where they end (none stepping)."""
    d = np.atleast_1d(np.asarray(distance, dtype=float))
    steps = np.maximum(4, np.ceil(d / 5)).astype(int)
    px, py = np.full(len(d), float(x)), np.full(len(d), float(y))
    for k in range(int(steps.max())):
        walking = k < steps
        yield px, py, walking
        heading = geometry.scenic_headings(FIELD, px[walking], py[walking], None)
        px[walking] -= np.sin(heading) * d[walking] / steps[walking]
        py[walking] += np.cos(heading) * d[walking] / steps[walking]
    yield px, py, np.zeros(len(d), dtype=bool)


def reference_follow(x: float, y: float, distance, geometry: MapGeometry = GEOMETRY):
    """Where Scenic's followFrom ends (:func:`reference_walk`), for one distance, or element-wise
    for an array of them."""
    *_, (px, py, _) = reference_walk(x, y, distance, geometry)
    return (float(px[0]), float(py[0])) if np.ndim(distance) == 0 else (px, py)


def end_heading(x: float, y: float) -> float:
    return float(GEOMETRY.scenic_headings(FIELD, np.array([x]), np.array([y]), None)[0])


def match(x: float, y: float, lo: float, hi: float, label: tuple[float, float, float], tol: float = 1e-6):
    """The scene query's answer and witness D for a car labeled at ``label`` behind an ego at (x, y)."""
    query = compile_scene(HEADER + PROGRAM.format(lo=lo, hi=hi), "follow.scenic")
    ego_heading = end_heading(x, y)
    trace = trace_of({"ego": ("Car", x, y, ego_heading), "c": ("Car", *label)})
    options = SceneOptions(Tolerance(tol, tol), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    result = query.match(trace, MAP, options)
    if not result.matched[0]:
        return False, None
    return True, next(v for k, v in result.values(0).items() if k.startswith("Range"))


STARTS = [((1.75, 2.0), 70.0), ((1.75, 17.3), 60.0), ((0.9, 31.0), 50.0), ((9.5, 55.5), 40.0), ((35.0, 60.4), 25.0)]
"""Ego positions, each with the longest walk that keeps a car's box on the lanes."""

LOW = 6.0
"""Shortest walk tried: the followed car (4.5 m long) must not overlap the ego."""

starts = st.sampled_from(STARTS)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(starts, st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_every_walk_ends_on_a_piece(start, where, slack):
    """Completeness of the pieces: the reference walk for any D ends where a piece holding D says,
    also when only the pieces that may end in a box around that end are asked for."""
    (x, y), longest = start
    distance = where * longest
    ex, ey = reference_follow(x, y, distance)
    for target in (None, np.array([[ex - slack, ex + 0.01, ey - 0.01, ey + slack]])):
        pieces = follow_pieces(
            GEOMETRY,
            FIELD,
            np.array([x]),
            np.array([y]),
            np.array([distance - 5 * slack]),
            np.array([distance + 3]),
            target,
        )
        holding = (pieces.lo <= distance) & (distance <= pieces.hi)
        assert holding.any()
        errors = np.maximum(np.abs(x + distance * pieces.ax - ex), np.abs(y + distance * pieces.ay - ey))
        assert errors[holding].min() <= 1e-9


@settings(max_examples=40, deadline=None, derandomize=True)
@given(starts, st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_a_planted_walk_matches_with_a_witness_that_reproduces_it(start, size, where):
    (x, y), longest = start
    lo, hi = LOW, LOW + (longest - LOW) * max(size, 0.01)
    width = hi - lo
    d = lo + where * width
    ex, ey = reference_follow(x, y, d)
    found, witness = match(x, y, lo, hi, (ex, ey, end_heading(ex, ey)), tol=1e-4)
    assert found
    assert lo <= witness <= hi
    wx, wy = reference_follow(x, y, witness)
    assert max(abs(wx - ex), abs(wy - ey)) <= 1e-4 + 1e-9
    assert abs(math.remainder(end_heading(wx, wy) - end_heading(ex, ey), 2 * math.pi)) <= 1e-4 + 1e-9


@settings(max_examples=40, deadline=None, derandomize=True)
@given(starts, st.floats(0.0, 1.0), st.floats(0.0, 1.0), st.floats(-0.08, 0.08), st.floats(-0.08, 0.08))
def test_answers_agree_with_a_dense_search(start, size, where, dx, dy):
    """A perturbed label: every match has a witness the reference reproduces (no false match), and
    a dense search over D finding a reproducing value means the query matches (no false miss)."""
    (x, y), longest = start
    lo, hi = LOW, LOW + (longest - LOW) * max(size, 0.01)
    width = hi - lo
    ex, ey = reference_follow(x, y, lo + where * width)
    label = (ex + dx, ey + dy, end_heading(ex, ey))
    tol = 0.05
    found, witness = match(x, y, lo, hi, label, tol=tol)
    if found:
        wx, wy = reference_follow(x, y, witness)
        assert max(abs(wx - label[0]), abs(wy - label[1])) <= tol + 1e-9
    rx, ry = reference_follow(x, y, np.linspace(lo, hi, 4001))
    headings = GEOMETRY.scenic_headings(FIELD, rx, ry, None)
    heading_ok = np.abs(np.remainder(headings - label[2] + math.pi, 2 * math.pi) - math.pi) <= tol
    close = np.maximum(np.abs(rx - label[0]), np.abs(ry - label[1])) <= tol
    if np.any(close & heading_ok):
        assert found


def test_without_lanes_the_walk_goes_north():
    """Off every lane Scenic's road direction is 0 (north): one piece, the end D metres north."""
    geometry = MapGeometry(RoadMap("empty", ()))
    pieces = follow_pieces(geometry, FIELD, np.array([3.0]), np.array([4.0]), np.array([5.0]), np.array([35.0]))
    assert np.allclose(pieces.ax, 0.0) and np.allclose(pieces.ay, 1.0) and np.all(pieces.heading == 0.0)
    assert pieces.lo.min() == 5.0 and pieces.hi.max() == 35.0


def test_a_label_off_the_walk_or_facing_away_does_not_match():
    ex, ey = reference_follow(1.75, 2.0, 30.0)
    assert match(1.75, 2.0, 10.0, 40.0, (ex, ey, end_heading(ex, ey)))[0]
    assert not match(1.75, 2.0, 10.0, 40.0, (ex + 0.01, ey, end_heading(ex, ey)))[0]
    assert not match(1.75, 2.0, 10.0, 40.0, (ex, ey, end_heading(ex, ey) + 0.01))[0]
    assert not match(1.75, 2.0, 31.0, 40.0, (ex, ey, end_heading(ex, ey)))[0]


def test_the_follow_operator_is_decided_the_same_way():
    program = "ego = new Car on road\np = follow roadDirection from ego for Range(10, 30)\nc = new Car at p"
    query = compile_scene(HEADER + program, "follow.scenic")
    options = SceneOptions(Tolerance(1e-6, 1e-6), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    ex, ey = reference_follow(1.75, 2.0, 25.0)
    on, off = (
        query.match(trace_of({"ego": ("Car", 1.75, 2.0, 0.0), "c": ("Car", x, ey, end_heading(ex, ey))}), MAP, options)
        for x in (ex, ex + 0.01)
    )
    assert on.matched.tolist() == [True] and off.matched.tolist() == [False]
    witness = next(v for k, v in on.values(0).items() if k.startswith("Range"))
    assert abs(witness - 25.0) <= 1e-5


def test_a_distance_bounded_by_another_random_variable():
    """``Range(d, 20)`` with ``d`` random: D's range comes from d's, and the pieces are exact."""
    program = "ego = new Car on road\nd = Range(8, 12)\nc = new Car following roadDirection from ego for Range(d, 20)"
    query = compile_scene(HEADER + program, "follow.scenic")
    options = SceneOptions(Tolerance(1e-6, 1e-6), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    for distance, expected in ((9.0, True), (15.0, True), (7.0, False), (21.0, False)):
        ex, ey = reference_follow(1.75, 2.0, distance)
        trace = trace_of({"ego": ("Car", 1.75, 2.0, 0.0), "c": ("Car", ex, ey, end_heading(ex, ey))})
        result = query.match(trace, MAP, options)
        assert result.matched.tolist() == [expected], distance
        if expected:
            values = result.values(0)
            d, walked = values["Range(8, 12)@3:5"], values["Range(d, 20)@4:50"]
            assert 8 <= d <= walked <= 20 and abs(walked - distance) <= 1e-5


@pytest.mark.parametrize("distance", ["Range(10, 1e9)", "Normal(20, 5)", "3e3"])
def test_a_walk_that_may_exceed_two_kilometres_is_a_user_error(distance):
    """Scenic would take up to 2e8 Euler steps: refused in one line instead of hanging."""
    program = f"ego = new Car on road\nc = new Car following roadDirection from ego for {distance}"
    query = compile_scene(HEADER + program, "follow.scenic")
    trace = trace_of({"ego": ("Car", 1.75, 2.0, 0.0), "c": ("Car", 1.75, 30.0, 0.0)})
    with pytest.raises(UserError, match="exceed 2000 m"):
        query.match(trace, MAP, SceneOptions(Tolerance(1e-6, 1e-6), correspondence={"c": "c"}, unknown_layers=ANYWHERE))


def test_a_requirement_on_the_followed_car_is_decided_on_each_piece():
    """A requirement on D itself sends each piece, rewritten, to the general solvers."""
    program = (
        "ego = new Car on road\nd = Range(10, 30)\nc = new Car following roadDirection from ego for d\nrequire d > 20"
    )
    query = compile_scene(HEADER + program, "follow.scenic")
    options = SceneOptions(Tolerance(1e-6, 1e-6), correspondence={"c": "c"}, unknown_layers=ANYWHERE)
    answers = []
    for d in (15.0, 25.0):
        ex, ey = reference_follow(1.75, 2.0, d)
        trace = trace_of({"ego": ("Car", 1.75, 2.0, 0.0), "c": ("Car", ex, ey, end_heading(ex, ey))})
        result = query.match(trace, MAP, options)
        answers.append(bool(result.matched[0]))
        if result.matched[0]:
            witness = next(v for k, v in result.values(0).items() if k.startswith("Range"))
            assert abs(witness - d) <= 1e-5
    assert answers == [False, True]


@pytest.mark.real_data
@pytest.mark.parametrize("town", ["Town01", "Town06"])
def test_the_pieces_of_carla_towns_hold_every_walk(town, maps_dir):
    """On real maps (centrelines that fold back where lane sections join, intersections whose
    lanes overlap): the reference walk from random lane points ends where a piece says."""
    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene.geometry import geometry_of

    geometry = geometry_of(read_map(maps_dir / f"{town}.xodr"))
    rng = np.random.default_rng(5)
    x0, y0, x1, y1 = geometry.map.bounds()
    x, y = rng.uniform(x0, x1, 4000), rng.uniform(y0, y1, 4000)
    on_lanes = np.unique(geometry.map.lanes_containing(x, y)[0])[:40]
    x, y = x[on_lanes], y[on_lanes]
    pieces = follow_pieces(geometry, FIELD, x, y, np.full(len(x), 10.0), np.full(len(x), 40.0))
    for row in range(len(x)):
        distances = rng.uniform(10.0, 40.0, 25)
        px, py = reference_follow(x[row], y[row], distances, geometry)
        mine = pieces.row == row
        for d, ex, ey in zip(distances, px, py):
            holding = mine & (pieces.lo <= d) & (d <= pieces.hi)
            errors = np.maximum(np.abs(x[row] + d * pieces.ax - ex), np.abs(y[row] + d * pieces.ay - ey))
            assert errors[holding].min() <= 1e-9, (row, d)


@pytest.mark.real_data
@pytest.mark.parametrize("town", ["Town01", "Town06"])
def test_the_linework_holds_every_lane_and_intersection_boundary(town, maps_dir):
    """Every edge of every part of every lane and intersection area (CARLA's areas are
    MultiPolygons) is linework: the road direction may change across each."""
    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene.follow_pieces import linework
    from scenegrep.scene.geometry import geometry_of

    geometry = geometry_of(read_map(maps_dir / f"{town}.xodr"))
    lw = linework(geometry)
    have = set(map(tuple, np.round(np.concatenate([lw.start, lw.end], 1), 9).tolist()))
    areas = list(geometry.map.lane_polygons) + [a.polygon for a in geometry.map.intersections]
    edges = 0
    for ring in shapely.get_rings(shapely.get_parts(np.array(areas, dtype=object))):
        coords = shapely.get_coordinates(ring)
        for edge in np.round(np.concatenate([coords[:-1], coords[1:]], 1), 9).tolist():
            if edge[:2] != edge[2:]:
                edges += 1
                assert tuple(edge) in have
    assert edges > 1000


@pytest.mark.real_data
@pytest.mark.parametrize("town", ["Town01", "Town06"])
def test_the_pieces_hold_every_walk_through_intersection_areas(town, maps_dir):
    """Walks from random points of the intersection areas end where a piece says, unless a step
    starts between the area's lanes (there Scenic takes the nearest lane, which the pieces read at
    their midpoint: the documented assumption of :mod:`scenegrep.scene.follow_pieces`)."""
    from scenegrep.readers.opendrive import read_map
    from scenegrep.scene.geometry import geometry_of

    geometry = geometry_of(read_map(maps_dir / f"{town}.xodr"))
    areas = shapely.union_all([a.polygon for a in geometry.map.intersections])
    rng = np.random.default_rng(7)
    x0, y0, x1, y1 = areas.bounds
    x, y = rng.uniform(x0, x1, 20000), rng.uniform(y0, y1, 20000)
    inside = np.flatnonzero(shapely.contains_xy(areas, x, y))[:40]
    x, y = x[inside], y[inside]
    pieces = follow_pieces(geometry, FIELD, x, y, np.full(len(x), 5.0), np.full(len(x), 30.0))
    checked = 0
    for row in range(len(x)):
        distances = rng.uniform(5.0, 30.0, 25)
        px, py = reference_follow(x[row], y[row], distances, geometry)
        mine = pieces.row == row
        for d, ex, ey in zip(distances, px, py):
            if _steps_between_lanes(geometry, areas, x[row], y[row], d):
                continue
            checked += 1
            holding = mine & (pieces.lo <= d) & (d <= pieces.hi)
            errors = np.maximum(np.abs(x[row] + d * pieces.ax - ex), np.abs(y[row] + d * pieces.ay - ey))
            assert errors[holding].min() <= 1e-9, (row, d)
    assert checked >= 500


def _steps_between_lanes(geometry: MapGeometry, areas, x: float, y: float, distance: float) -> bool:
    """Whether a step of the reference walk starts in an intersection area but in none of its lanes."""
    return any(
        walking[0] and shapely.contains_xy(areas, px[0], py[0]) and not len(geometry.map.lanes_containing(px, py)[0])
        for px, py, walking in reference_walk(x, y, distance, geometry)
    )


@pytest.mark.slow
@pytest.mark.real_data
def test_scenic_samples_match_and_perturbations_do_not(maps_dir):
    from pathlib import Path

    from scenegrep.synth.ground_truth import check_program

    program = Path(__file__).resolve().parents[2] / "examples" / "ground_truth" / "following.scenic"
    result = check_program(program, 40, maps_dir / "Town01.xodr", seed=3, random_perturbations=False)
    assert result.false_negatives == 0
    for violation, (rejected, total) in result.violations.items():
        assert rejected == total, violation
