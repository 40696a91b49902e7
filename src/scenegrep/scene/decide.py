"""Deciding one group for all rows: is there a value of its random variables that reproduces
the labeled features (within tolerance) and satisfies its requirements?

The fast paths are vectorised closed forms over all rows at once:

* no unknowns: evaluate and compare;
* one scalar unknown ``u`` on which every constraint is affine: each constraint
  ``lo <= a*u + c <= hi`` is an interval of ``u``; intersect them with ``u``'s
  range, then check the (at most one) heading constraint modulo 2π on the
  interval of values it takes there;
* one random point pinned by the position features (``position = p + known``):
  the tolerance box of ``p`` must meet the point's region (R-tree
  point-in-polygon, exact).

Anything else is decided row by row by :mod:`.solvers` (linear programming,
SMT, interval branch-and-prune).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .dependencies import Group
from .evaluate import Affine, Evaluator, NotAffine
from .solvers import decide_rows
from .terms import Term
from .tolerance import Tolerance

TWO_PI = 2 * np.pi


@dataclass
class Linear:
    """``lo <= form <= hi`` over rows; ``angle`` constraints hold modulo 2π."""

    form: Affine
    lo: np.ndarray
    hi: np.ndarray
    angle: bool = False


def decide(ev: Evaluator, group: Group, tolerance: Tolerance) -> np.ndarray:
    """Which of the evaluator's original rows have a feasible assignment (bool array)."""
    for leaf in sorted((u for u in group.unknowns if u.op == "choice"), key=repr):
        ev.expand_choice(leaf)
    ev.unknowns = frozenset(u for u in group.unknowns if u.op != "choice")
    ok = decide_expanded(ev, group, tolerance)
    found = np.zeros(len(ev.rows), dtype=bool)
    found[ev.origin[ok]] = True
    return found


def decide_expanded(ev: Evaluator, group: Group, tolerance: Tolerance) -> np.ndarray:
    if not ev.unknowns:
        return _direct(ev, group, tolerance)
    try:
        linear = _linear_constraints(ev, group, tolerance)
    except NotAffine:
        linear = None
    if linear is not None:
        scalars = {u for c in linear for u in c.form.coefs}
        points = {u.value[0] for u in ev.unknowns if u.op == "point"}
        turning = sum(1 for c in linear if c.angle and c.form.coefs)
        if not points and len(scalars) <= 1 and turning <= 1:
            return _one_unknown(ev, linear)
        pinned = _pinned_point(ev, linear, points)
        if pinned is not None:
            return pinned
    return decide_rows(ev, group, tolerance)


def _direct(ev: Evaluator, group: Group, tolerance: Tolerance) -> np.ndarray:
    for feature in group.features:
        ev.value(feature.term)
        ev.value(feature.observed)
    for requirement in group.requirements:
        ev.value(requirement.condition)
    ok = np.ones(ev.size, dtype=bool)
    for feature in group.features:
        diff = ev.memo[feature.term] - ev.memo[feature.observed]
        if feature.is_angle:
            diff = np.pi - np.mod(np.pi - diff, TWO_PI)
        ok &= np.abs(diff) <= tolerance.of(feature)
    for requirement in group.requirements:
        ok &= ev.memo[requirement.condition].astype(bool)
    return ok


# ---------------------------------------------------------------------------- linear systems
def _linear_constraints(ev: Evaluator, group: Group, tolerance: Tolerance) -> list[Linear]:
    """The group's constraints as affine ones, with the ranges of its random variables; raises
    :class:`NotAffine` when some constraint is not (a conjunction of) affine comparisons.

    Built twice: the first pass computes (and may expand rows), the second reads the memoised,
    re-indexed results, so every array has the final number of rows.
    """
    _build_linear(ev, group, tolerance)
    return _build_linear(ev, group, tolerance)


def _build_linear(ev: Evaluator, group: Group, tolerance: Tolerance) -> list[Linear]:
    constraints: list[Linear] = []
    for feature in group.features:
        form = ev.affine(feature.term)
        observed = ev.value(feature.observed)
        tol = tolerance.of(feature)
        constraints.append(Linear(form, observed - tol, observed + tol, feature.is_angle))
    for requirement in group.requirements:
        constraints.extend(_comparisons(ev, requirement.condition))
    for u in ev.unknowns:
        if u.op == "var":
            low, high = ev.value(u.value.low), ev.value(u.value.high)
            constraints.append(Linear(ev.affine(u), low, high))
    return constraints


def _comparisons(ev: Evaluator, condition: Term) -> list[Linear]:
    """A requirement that is a conjunction of comparisons of affine terms, as constraints.

    Strict and non-strict comparisons are the same here (they differ on a set of measure zero).
    """
    if condition.op == "and":
        return [c for part in condition.args for c in _comparisons(ev, part)]
    negated = condition.op == "not" and condition.args[0].op in ("lt", "le")
    comparison = condition.args[0] if negated else condition
    if comparison.op not in ("lt", "le"):
        if ev.depends_on_unknowns(condition):
            raise NotAffine(f"{condition.op} of unknowns")
        ok = ev.value(condition).astype(float)
        return [Linear(Affine(ok, {}), np.ones(ev.size), np.ones(ev.size))]
    left, right = (ev.affine(a) for a in comparison.args)
    difference = right.plus(left, -1.0) if negated else left.plus(right, -1.0)
    return [Linear(difference, np.full(ev.size, -np.inf), np.zeros(ev.size))]


def _one_unknown(ev: Evaluator, constraints: list[Linear]) -> np.ndarray:
    """Feasibility when at most one scalar unknown appears (vectorised interval intersection)."""
    ok, low, high, angles = _unknown_interval(ev, constraints)
    for c, coef in angles:
        ends = (coef * low + c.form.const, coef * high + c.form.const)
        lo_v, hi_v = np.minimum(*ends), np.maximum(*ends)
        ok &= _angle_gap(lo_v, hi_v, (c.lo + c.hi) / 2) <= (c.hi - c.lo) / 2
    return ok


def _unknown_interval(ev: Evaluator, constraints: list[Linear]):
    """(feasible so far, low, high, heading constraints with their coefficients): the interval of
    the one unknown that the non-heading constraints allow, per row."""
    n = ev.size
    low, high = np.full(n, -np.inf), np.full(n, np.inf)
    ok = np.ones(n, dtype=bool)
    angles = []
    for c in constraints:
        coef = next(iter(c.form.coefs.values()), np.zeros(n))
        if c.angle and np.any(coef != 0):
            angles.append((c, coef))
            continue
        if c.angle:
            ok &= _angle_gap(c.form.const, c.form.const, (c.lo + c.hi) / 2) <= (c.hi - c.lo) / 2
            continue
        fixed = coef == 0
        ok &= ~fixed | ((c.lo <= c.form.const) & (c.form.const <= c.hi))
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (c.lo - c.form.const) / coef
            b = (c.hi - c.form.const) / coef
        low = np.where(fixed, low, np.maximum(low, np.minimum(a, b)))
        high = np.where(fixed, high, np.minimum(high, np.maximum(a, b)))
    return ok & (low <= high), low, high, angles


def _angle_gap(lo: np.ndarray, hi: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The smallest |wrap(v - target)| over v in [lo, hi] (0 when the interval reaches the target mod 2π)."""
    width = hi - lo
    with np.errstate(invalid="ignore"):
        ahead = np.mod(target - lo, TWO_PI)  # from lo forward to the next copy of the target
    inside = (ahead <= width) | (width >= TWO_PI)
    return np.where(inside, 0.0, np.minimum(ahead - width, TWO_PI - ahead))


def _pinned_point(ev: Evaluator, constraints: list[Linear], points: set) -> np.ndarray | None:
    """Feasibility when the only unknown is a random point the position features pin down."""
    pinned = _pinned_box(ev, constraints, points)
    if pinned is None:
        return None
    (x_lo, x_hi), (y_lo, y_hi), rest, region = pinned
    ok = (x_lo <= x_hi) & (y_lo <= y_hi)
    for c in rest:
        ok &= (c.lo <= c.form.const) & (c.form.const <= c.hi)
    return ok & ev.geometry.boxes_meet(region, x_lo, x_hi, y_lo, y_hi, ev.value)


def _pinned_box(ev: Evaluator, constraints: list[Linear], points: set):
    """((x_lo, x_hi), (y_lo, y_hi), constraints without unknowns, region) when the one random
    point's coordinates each appear alone with coefficient 1, else None."""
    if len(points) != 1 or len(ev.unknowns) != 2:
        return None
    point = next(iter(points))
    px, py = sorted(ev.unknowns, key=lambda u: u.value[1])
    box: dict[Term, tuple[np.ndarray, np.ndarray]] = {}
    rest = []
    for c in constraints:
        if not c.form.coefs:
            rest.append(c)
            continue
        if c.angle or len(c.form.coefs) != 1:
            return None
        ((u, coef),) = c.form.coefs.items()
        if not np.all(coef == 1):
            return None
        lo, hi = c.lo - c.form.const, c.hi - c.form.const
        if u in box:
            lo, hi = np.maximum(lo, box[u][0]), np.minimum(hi, box[u][1])
        box[u] = (lo, hi)
    if set(box) != {px, py}:
        return None
    for term in point.region.terms():
        if ev.depends_on_unknowns(term):
            return None
        ev.value(term)
    return box[px], box[py], rest, point.region


def _closed_form_parts(ev: Evaluator, group: Group, tolerance: Tolerance) -> tuple[list[Linear], set, set] | None:
    """The group's constraints when all are affine in its unknowns, with the scalar unknowns they
    involve and the random points among the unknowns; None when some constraint is not affine."""
    try:
        constraints = _linear_constraints(ev, group, tolerance)
    except NotAffine:
        return None
    return (
        constraints,
        {u for c in constraints for u in c.form.coefs},
        {u.value[0] for u in ev.unknowns if u.op == "point"},
    )


def closed_form_witness(ev: Evaluator, group: Group, tolerance: Tolerance, row: int) -> dict[Term, float] | None:
    """Values of the group's unknowns satisfying row ``row`` when a closed form applies (one unknown
    in affine constraints, or a pinned point), checked against every constraint; else None."""
    parts = _closed_form_parts(ev, group, tolerance)
    if parts is None:
        return None
    constraints, scalars, points = parts
    if not points and len(scalars) == 1:
        (u,) = scalars
        ok, low, high, angles = _unknown_interval(ev, constraints)
        candidates = _candidates(float(low[row]), float(high[row]), angles, row)
        found = [v for v in candidates if _holds(constraints, row, v)]
        return {u: found[0]} if ok[row] and found else None
    pinned = _pinned_box(ev, constraints, points)
    if pinned is None:
        return None
    (x_lo, x_hi), (y_lo, y_hi), _, region = pinned
    px, py = sorted(ev.unknowns, key=lambda u: u.value[1])
    x, y = (x_lo[row] + x_hi[row]) / 2, (y_lo[row] + y_hi[row]) / 2
    inside = ev.geometry.contains_points(region, np.array([x]), np.array([y]), lambda t: ev.value(t)[row : row + 1])
    return {px: float(x), py: float(y)} if inside[0] else None


def _candidates(low: float, high: float, angles: list, row: int) -> list[float]:
    """Values to try for one unknown: the middle of its interval (or a finite point of it), and for a
    heading constraint the values in the interval that meet its target exactly."""
    finite_low, finite_high = max(low, -1e9), min(high, 1e9)
    values = [(finite_low + finite_high) / 2 if low <= high else low]
    for c, coef in angles:
        a, target = float(coef[row]), float((c.lo[row] + c.hi[row]) / 2 - c.form.const[row])
        if a == 0:
            continue
        centre = (finite_low + finite_high) / 2 * a
        k0 = round((centre - target) / TWO_PI)
        values += [(target + TWO_PI * k) / a for k in range(k0 - 2, k0 + 3)]
    return [v for v in values if low <= v <= high]


def _holds(constraints: list[Linear], row: int, value: float) -> bool:
    for c in constraints:
        coef = next(iter(c.form.coefs.values()), None)
        v = c.form.const[row] + (0.0 if coef is None else coef[row] * value)
        if c.angle:
            middle, half = (c.lo[row] + c.hi[row]) / 2, (c.hi[row] - c.lo[row]) / 2
            if _angle_gap(np.array([v]), np.array([v]), np.array([middle]))[0] > half:
                return False
        elif not c.lo[row] <= v <= c.hi[row]:
            return False
    return True


def closed_form_intervals(
    ev: Evaluator, group: Group, tolerance: Tolerance
) -> dict[Term, tuple[np.ndarray, np.ndarray]] | None:
    """Per unknown, the lowest and highest value (arrays over the evaluator's current rows) that
    satisfies each row's constraints, where a closed form applies: exact for one unknown in
    affine constraints with at most one heading constraint modulo 2π (the hull of its feasible
    values); for a random point pinned by the position features, the tolerance box of its
    coordinates (an outer bound: the point's region may cut the box). None otherwise. Rows that
    are not feasible get meaningless values (the caller masks them)."""
    parts = _closed_form_parts(ev, group, tolerance)
    if parts is None:
        return None
    constraints, scalars, points = parts
    if not points and len(scalars) == 1:
        (u,) = scalars
        _, low, high, angles = _unknown_interval(ev, constraints)
        if len(angles) > 1:
            return None
        for c, coef in angles:
            low, high = _angle_hull(c, coef, low, high)
        return {u: (low, high)}
    pinned = _pinned_box(ev, constraints, points)
    if pinned is None:
        return None
    (x_lo, x_hi), (y_lo, y_hi), _, _ = pinned
    px, py = sorted(ev.unknowns, key=lambda u: u.value[1])
    return {px: (x_lo, x_hi), py: (y_lo, y_hi)}


def _angle_hull(c: Linear, coef: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The hull of the values u in [low, high] for which ``coef * u + const`` lies in the heading
    window [c.lo, c.hi] modulo 2π: the window's first entry at or after the lowest value the term
    takes, and its last exit at or before the highest (rows where coef is 0 keep [low, high])."""
    ends = (coef * low + c.form.const, coef * high + c.form.const)
    v_lo, v_hi = np.minimum(*ends), np.maximum(*ends)
    width = c.hi - c.lo
    with np.errstate(invalid="ignore"):
        inside_lo = (np.mod(v_lo - c.lo, TWO_PI) <= width) | (width >= TWO_PI)
        inside_hi = (np.mod(v_hi - c.lo, TWO_PI) <= width) | (width >= TWO_PI)
        first = np.where(inside_lo | ~np.isfinite(v_lo), v_lo, v_lo + np.mod(c.lo - v_lo, TWO_PI))
        last = np.where(inside_hi | ~np.isfinite(v_hi), v_hi, v_hi - np.mod(v_hi - c.hi, TWO_PI))
    turning = coef != 0
    safe = np.where(turning, coef, 1.0)
    a, b = (first - c.form.const) / safe, (last - c.form.const) / safe
    return np.where(turning, np.minimum(a, b), low), np.where(turning, np.maximum(a, b), high)
