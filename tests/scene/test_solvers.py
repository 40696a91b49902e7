"""The row solvers on small systems with answers worked out by hand."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene.tolerance import Tolerance
from scenegrep.scene.geometry import GEOMETRY_CACHE_SIZE, MapGeometry, geometry_of
from scenegrep.scene.regions import MapField, MapRegion, Sector
from scenegrep.scene.shapes import points_in_sector
from scenegrep.scene.solvers import linear, smt, solve
from scenegrep.scene.solvers.branch_prune import BranchAndPrune, covering_arc
from scenegrep.scene.solvers.problem import Bound, PointUnknown, Problem
from scenegrep.scene.terms import RandomPoint, RandomVariable, TermFactory
from tests.model.maps import synthetic_map
from tests.scene.frames import MAP

GEOMETRY = MapGeometry(MAP)


def variable(f: TermFactory, name: str, low: float, high: float):
    return f.var(RandomVariable(name, f.const(low), f.const(high)))


def test_covering_arc_crosses_the_branch_cut():
    arc = covering_arc(np.array([3.1, -3.1]))
    assert arc.lo < 3.1 < arc.hi and arc.hi - arc.lo < 0.09
    assert arc.lo <= math.pi < arc.hi  # unwrapped: -3.1 appears as 2π - 3.1
    spread = covering_arc(np.array([0.0, 2.0, 4.0]))  # the widest gap (2.28 rad) is from 4 round to 0
    assert abs(spread.lo) < 1e-9 and abs(spread.hi - 4.0) < 1e-9


def test_linear_heading_window_wraps():
    f = TermFactory()
    v = variable(f, "v", 10.0, 14.0)  # radians: 10..14 covers 4π - 0.57 .. 4π + 1.43
    problem = Problem(f, [v], {v: (10.0, 14.0)}, bounds=[Bound(v, 0.2, 0.3, angle=True)])
    witness = linear.solve(problem, GEOMETRY, {v: (10.0, 14.0)})
    assert witness is not None and abs(witness[v] - (4 * math.pi + 0.25)) <= 0.05 + 1e-9
    problem.bounds = [Bound(v, 2.0, 2.1, angle=True)]  # 2 + 2πk is never in [10, 14]
    assert linear.solve(problem, GEOMETRY, {v: (10.0, 14.0)}) is None


def test_a_point_in_a_polygonal_layer():
    f = TermFactory()
    point = RandomPoint("p", MapRegion("crossing"))
    x, y = f.point(point)
    for (px, py), expected in (((2.0, 61.0), True), ((2.0, 70.0), False)):
        problem = Problem(f, points=[PointUnknown(point, x, y, point.region)])
        problem.bounds = [Bound(x, px - 1e-6, px + 1e-6), Bound(y, py - 1e-6, py + 1e-6)]
        boxes = {x: (-10.0, 10.0), y: (0.0, 100.0)}
        assert (linear.solve(problem, GEOMETRY, boxes) is not None) is expected
        assert (smt.solve(problem, GEOMETRY, boxes)[0] == "sat") is expected
        assert solve(problem, GEOMETRY, Tolerance()).feasible is expected


@settings(max_examples=200)
@given(
    px=st.floats(-20, 20),
    py=st.floats(-20, 20),
    heading=st.floats(-math.pi, math.pi),
    angle=st.sampled_from([math.pi / 2, math.pi, 4.0, math.tau]),
)
def test_z3_sector_encoding_agrees_with_the_exact_test(px, py, heading, angle):
    f = TermFactory()
    point = RandomPoint("p", Sector(f.const(1.0), f.const(2.0), f.const(15.0), f.const(heading), f.const(angle)))
    x, y = f.point(point)
    problem = Problem(f, points=[PointUnknown(point, x, y, point.region)])
    problem.bounds = [Bound(x, px, px), Bound(y, py, py)]
    verdict, _ = smt.solve(problem, GEOMETRY, {x: (px, px), y: (py, py)})
    inside = points_in_sector(np.array([px]), np.array([py]), 1.0, 2.0, 15.0, heading, angle)[0]
    boundary = abs(math.hypot(px - 1.0, py - 2.0) - 15.0) < 1e-9
    assert boundary or (verdict == "sat") == bool(inside)


def test_branch_and_prune_solves_a_polar_placement():
    # (x, y) = r (-sin t, cos t) with r in [5, 10], t in [-0.35, 0.35]: (-2, 6) has r 6.32, t 0.32
    f = TermFactory()
    r, t = variable(f, "r", 5, 10), variable(f, "t", -0.35, 0.35)
    x = f.op("mul", r, f.op("neg", f.op("sin", t)))
    y = f.op("mul", r, f.op("cos", t))
    problem = Problem(f, [r, t], {r: (5.0, 10.0), t: (-0.35, 0.35)})
    problem.bounds = [Bound(x, -2 - 1e-6, -2 + 1e-6), Bound(y, 6 - 1e-6, 6 + 1e-6)]
    outcome = BranchAndPrune(problem, GEOMETRY, 1e-6).run()
    assert outcome.status == "sat"
    assert abs(outcome.witness[r] - math.hypot(2, 6)) < 1e-5
    problem.bounds = [Bound(x, -5 - 1e-6, -5 + 1e-6), Bound(y, 6 - 1e-6, 6 + 1e-6)]  # bearing 0.69 rad: too wide
    assert BranchAndPrune(problem, GEOMETRY, 1e-6).run().status == "unsat"


def test_a_point_on_the_curb_is_solved_per_segment():
    # the curb runs north along x = -3.5; a point on it with the curb's heading, then 2 m to its left
    f = TermFactory()
    point = RandomPoint("spot", MapRegion("curb"))
    x, y = f.point(point)
    heading = f.op("field", x, y, value=MapField("curb"))
    left_x = f.op("sub", x, f.op("mul", f.const(2.0), f.op("cos", heading)))
    problem = Problem(f, points=[PointUnknown(point, x, y, point.region)])
    problem.bounds = [Bound(left_x, -5.5 - 1e-6, -5.5 + 1e-6), Bound(y, 30 - 1e-6, 30 + 1e-6)]
    outcome = solve(problem, GEOMETRY, Tolerance())
    assert outcome.status == "sat" and outcome.solver == "linear"
    assert abs(outcome.witness[x] + 3.5) < 1e-6
    problem.bounds[0] = Bound(left_x, -5.0 - 1e-6, -5.0 + 1e-6)
    assert not solve(problem, GEOMETRY, Tolerance()).feasible


def test_the_geometry_of_a_map_is_shared_and_the_cache_is_bounded():
    assert geometry_of(MAP) is geometry_of(MAP)
    assert geometry_of(None) is not geometry_of(None)
    first = geometry_of(MAP)
    others = [synthetic_map() for _ in range(GEOMETRY_CACHE_SIZE)]
    assert len({id(geometry_of(m)) for m in others}) == GEOMETRY_CACHE_SIZE
    assert geometry_of(MAP) is not first  # evicted by the newer maps, rebuilt
    assert geometry_of(others[-1]).map is others[-1]
