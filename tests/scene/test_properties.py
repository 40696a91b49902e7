"""Property tests of the scene query against small brute-force references written here.

* ``ahead of ego by Range(a, b)`` on the straight lanes of the synthetic map, with labels
  perturbed at random, against a reference that searches the gap by ternary search on the
  (convex) largest coordinate error, and tries every correspondence by brute force;
* renaming and reordering label objects never changes an answer, and adding objects never
  removes a match (the correspondence is a search, and it is injective, not exact);
* the three row solvers agree on random linear systems: linear programming and z3 decide them
  exactly, branch-and-prune never refutes a system they satisfy.
"""

from __future__ import annotations

import itertools
import math

from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene.geometry import MapGeometry
from scenegrep.scene.solvers import linear, smt
from scenegrep.scene.solvers.branch_prune import BranchAndPrune
from scenegrep.scene.solvers.problem import Bound, Problem
from scenegrep.scene.terms import RandomVariable, TermFactory
from tests.scene.frames import MAP, matches

TOL = 1e-3
LENGTH = 4.5


def reference_ahead(frame: dict, low: float, high: float) -> bool:
    """Some label car other than the ego sits 'ahead of ego by d' for a d in [low, high], every
    coordinate within TOL (ternary search on the convex max error), heading within TOL."""
    _, ex, ey, eh = frame["ego"]
    for oid, (_, x, y, h) in frame.items():
        if oid == "ego" or abs(math.remainder(h - eh, 2 * math.pi)) > TOL:
            continue

        def error(d: float, x: float = x, y: float = y) -> float:
            reach = LENGTH / 2 + d + LENGTH / 2
            return max(abs(x - (ex - math.sin(eh) * reach)), abs(y - (ey + math.cos(eh) * reach)))

        a, b = low, high
        for _ in range(200):
            m1, m2 = a + (b - a) / 3, b - (b - a) / 3
            a, b = (a, m2) if error(m1) <= error(m2) else (m1, b)
        if error((a + b) / 2) <= TOL + 1e-9:
            return True
    return False


def _noise(scale: float) -> st.SearchStrategy[float]:
    """Zero, noise within the tolerance, or noise up to ``scale`` (mostly beyond it)."""
    return st.one_of(st.just(0.0), st.floats(-TOL / 2, TOL / 2), st.floats(-scale, scale))


cars = st.tuples(
    st.floats(0, 16),  # gap from the ego's box
    _noise(0.01),  # lateral offset (m)
    _noise(0.004),  # heading offset (rad)
    _noise(0.004),  # longitudinal jitter (m)
)


@settings(max_examples=150)
@given(
    ego_y=st.floats(5, 40), cars=st.lists(cars, min_size=1, max_size=3), low=st.floats(2, 8), width=st.floats(0.5, 6)
)
def test_ahead_of_against_brute_force(ego_y, cars, low, width):
    high = low + width
    frame = {"ego": ("Car", 1.75, ego_y, 0.0)}
    for k, (gap, lateral, turn, jitter) in enumerate(cars):
        y = ego_y + LENGTH + gap + jitter
        frame[f"c{k}"] = ("Car", 1.75 + lateral, y, turn)
    program = f"ego = new Car on road\nc = new Car ahead of ego by Range({low!r}, {high!r})"
    assert matches(program, frame, position=TOL, heading=TOL) == [reference_ahead(frame, low, high)]


@settings(max_examples=60)
@given(
    gaps=st.lists(st.floats(1, 6), min_size=2, max_size=2),
    extra=st.lists(st.tuples(st.floats(-3, 7), st.floats(0, 100), st.sampled_from([0.0, math.pi])), max_size=3),
    order=st.randoms(use_true_random=False),
    shift=st.sampled_from([0.0, 0.0, 0.3]),
)
def test_names_order_and_extra_objects(gaps, extra, order, shift):
    program = "ego = new Car on road\na = new Car ahead of ego by Range(1, 6)\nb = new Car ahead of a by Range(1, 6)"
    ego_y = 10.0
    ya = ego_y + LENGTH + gaps[0]
    yb = ya + LENGTH + gaps[1]
    base = {"ego": ("Car", 1.75, ego_y, 0.0), "a": ("Car", 1.75, ya, 0.0), "b": ("Car", 1.75, yb, 0.0)}
    if shift:
        base["b"] = ("Car", 1.75 + shift, yb, 0.0)
    expected = reference_two(base, 1.0, 6.0)
    assert matches(program, base) == [expected]
    names = ["p", "q", "r", "s", "t"]
    order.shuffle(names)
    renamed = {"ego": base["ego"], names[0]: base["b"], names[1]: base["a"]}
    assert matches(program, renamed) == [expected]
    crowded = dict(renamed)
    for k, (x, y, h) in enumerate(extra):
        crowded[f"z{k}"] = ("Car", x, y, h)
    # extra objects never hide a match, and they make one only where the brute force finds one
    crowded_expected = reference_two(crowded, 1.0, 6.0)
    assert crowded_expected or not expected
    assert matches(program, crowded) == [crowded_expected]


def reference_two(frame: dict, low: float, high: float) -> bool:
    """Brute force over ordered pairs of distinct non-ego cars: a ahead of ego, b ahead of a, no two
    of the three boxes (nor the other label cars' boxes... which Scenic does not ask) overlapping."""
    from scenegrep.scene.shapes import boxes_overlap

    _, ex, ey, _ = frame["ego"]
    others = [k for k in frame if k != "ego"]

    def ahead(front, back) -> bool:
        _, fx, fy, fh = frame[front]
        _, bx, by, bh = frame[back]
        gap = fy - by - LENGTH
        return abs(fx - bx) <= 1e-6 and abs(fh) <= 1e-6 and low - 1e-6 <= gap <= high + 1e-6 and fx == 1.75

    def apart(p, q) -> bool:
        a = tuple([v] for v in (*frame[p][1:4], LENGTH - 2e-6, 2.0 - 2e-6))
        b = tuple([v] for v in (*frame[q][1:4], LENGTH - 2e-6, 2.0 - 2e-6))
        return not boxes_overlap(a, b)[0]

    for a, b in itertools.permutations(others, 2):
        if ahead(a, "ego") and ahead(b, a) and apart("ego", a) and apart("ego", b) and apart(a, b):
            return True
    return False


# ---------------------------------------------------------------------------- solvers agree
def _linear_problem(data) -> Problem:
    f = TermFactory()
    count = data.draw(st.integers(1, 3))
    variables = []
    problem = Problem(f)
    for i in range(count):
        low = data.draw(st.integers(-5, 5))
        high = low + data.draw(st.integers(0, 6))
        v = f.var(RandomVariable(f"v{i}", f.const(low), f.const(high)))
        variables.append(v)
        problem.scalars.append(v)
        problem.ranges[v] = (float(low), float(high))
    for _ in range(data.draw(st.integers(1, 3))):
        term = f.const(data.draw(st.integers(-3, 3)))
        for v in variables:
            term = f.op("add", term, f.op("mul", f.const(data.draw(st.integers(-3, 3))), v))
        centre = data.draw(st.integers(-10, 10))
        half = data.draw(st.sampled_from([0.0, 0.5, 2.0]))
        problem.bounds.append(Bound(term, centre - half, centre + half))
    return problem


@settings(max_examples=60)
@given(data=st.data())
def test_row_solvers_agree_on_linear_systems(data):
    problem = _linear_problem(data)
    geometry = MapGeometry(MAP)
    boxes = dict(problem.ranges)
    assert linear.is_linear(problem, geometry) and smt.is_polynomial(problem)
    lp = linear.solve(problem, geometry, boxes)
    verdict, _ = smt.solve(problem, geometry, boxes)
    assert (lp is not None) == (verdict == "sat")
    outcome = BranchAndPrune(problem, geometry, delta=1e-6, budget=2_000).run()
    if lp is not None:
        assert outcome.status != "unsat"
    if outcome.status == "sat":
        assert lp is not None
