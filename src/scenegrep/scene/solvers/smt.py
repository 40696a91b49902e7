"""Polynomial systems, decided by the z3 SMT solver (nonlinear real arithmetic, complete for polynomials).

A problem is polynomial when its terms use only + - * / (by anything), integer
powers, ``abs``, ``min``, ``max``, ``sqrt`` (encoded with an auxiliary variable
``s >= 0, s*s = x``), comparisons and logic, and its random points lie in
polygonal map regions (a disjunction of triangles within the point's box) or in
sectors and discs (a quadratic and two half-planes). Constants are the exact
rationals of their floats. Heading bounds hold modulo 2π: the multiples of 2π
the term's range allows form a disjunction. z3 answers sat (with a model,
verified exactly afterwards), unsat, or unknown within its time limit (the
caller then falls back to branch-and-prune).
"""

from __future__ import annotations

import math
from fractions import Fraction

from ..geometry import MapGeometry
from ..regions import Intersection, Region, Sector
from ..terms import Term
from .linear import NotLinear, triangles, turns
from .problem import Problem

TIMEOUT_MS = 2000

_POLYNOMIAL = {
    "add",
    "sub",
    "mul",
    "div",
    "neg",
    "pow",
    "abs",
    "min",
    "max",
    "sqrt",
    "lt",
    "le",
    "eq",
    "ne",
    "and",
    "or",
    "not",
    "ite",
}


class NotPolynomial(Exception):
    """The problem uses functions outside polynomial arithmetic."""


def _rational(value: float):
    import z3

    if not math.isfinite(value):
        raise NotPolynomial("infinite constant")
    fraction = Fraction(value)
    return z3.Q(fraction.numerator, fraction.denominator)


class Encoder:
    """Translates specialised terms into z3 expressions, collecting side conditions."""

    def __init__(self, unknowns: list[Term]):
        import z3

        self.z3 = z3
        self.symbols = {u: z3.Real(f"u{i}") for i, u in enumerate(unknowns)}
        self.side: list = []
        self.memo: dict[Term, object] = {}

    def __call__(self, term: Term):
        if term in self.memo:
            return self.memo[term]
        result = self._encode(term)
        self.memo[term] = result
        return result

    def _encode(self, term: Term):
        z3 = self.z3
        if term in self.symbols:
            return self.symbols[term]
        if term.op == "const":
            if term.kind == "bool":
                return z3.BoolVal(bool(term.value))
            return _rational(float(term.value))
        if term.op not in _POLYNOMIAL:
            raise NotPolynomial(term.op)
        args = [self(a) for a in term.args]
        return _OPERATIONS[term.op](self, term, args)

    def sqrt(self, x):
        s = self.z3.FreshReal("sqrt")
        self.side += [s >= 0, s * s == x, x >= 0]
        return s


_OPERATIONS = {
    "add": lambda e, t, a: a[0] + a[1],
    "sub": lambda e, t, a: a[0] - a[1],
    "mul": lambda e, t, a: a[0] * a[1],
    "div": lambda e, t, a: a[0] / a[1],
    "neg": lambda e, t, a: -a[0],
    "pow": lambda e, t, a: a[0] ** t.value if t.value else _rational(1.0),
    "abs": lambda e, t, a: e.z3.If(a[0] >= 0, a[0], -a[0]),
    "min": lambda e, t, a: e.z3.If(a[0] <= a[1], a[0], a[1]),
    "max": lambda e, t, a: e.z3.If(a[0] >= a[1], a[0], a[1]),
    "sqrt": lambda e, t, a: e.sqrt(a[0]),
    "lt": lambda e, t, a: a[0] < a[1],
    "le": lambda e, t, a: a[0] <= a[1],
    "eq": lambda e, t, a: a[0] == a[1],
    "ne": lambda e, t, a: a[0] != a[1],
    "and": lambda e, t, a: e.z3.And(*a),
    "or": lambda e, t, a: e.z3.Or(*a),
    "not": lambda e, t, a: e.z3.Not(a[0]),
    "ite": lambda e, t, a: e.z3.If(*a),
}


def _region(encoder: Encoder, region: Region, x, y, point, geometry: MapGeometry, boxes) -> object:
    z3 = encoder.z3
    if isinstance(region, Intersection):
        return z3.And(*(_region(encoder, p, x, y, point, geometry, boxes) for p in region.parts))
    if isinstance(region, Sector):
        return _sector(encoder, region, x, y)
    try:
        pieces = triangles(region, boxes[point.x], boxes[point.y], geometry)
    except NotLinear as error:
        raise NotPolynomial(str(error)) from None
    if not pieces:
        return z3.BoolVal(False)
    cases = []
    for (ax, ay), (bx, by), (cx, cy) in pieces:
        sign = 1.0 if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) >= 0 else -1.0
        sides = []
        for (px, py), (qx, qy) in (((ax, ay), (bx, by)), ((bx, by), (cx, cy)), ((cx, cy), (ax, ay))):
            cross = (_rational(qx - px)) * (y - _rational(py)) - (_rational(qy - py)) * (x - _rational(px))
            sides.append(cross * _rational(sign) >= 0)
        cases.append(z3.And(*sides))
    return z3.Or(*cases)


def _sector(encoder: Encoder, sector: Sector, x, y) -> object:
    z3 = encoder.z3
    cx, cy, radius, heading, angle = (float(t.value) for t in sector.terms())
    dx, dy = x - _rational(cx), y - _rational(cy)
    inside = dx * dx + dy * dy <= _rational(radius) ** 2
    if angle >= 2 * math.pi:
        return inside
    # the direction (sin, cos) form of a heading h is (-sin h, cos h); the point's bearing lies within
    # the half-angle of the axis when it is on the inner side of both edge rays
    half = angle / 2
    left = (-math.sin(heading + half), math.cos(heading + half))
    right = (-math.sin(heading - half), math.cos(heading - half))
    inner_left = _rational(left[0]) * dy - _rational(left[1]) * dx <= 0
    inner_right = _rational(right[0]) * dy - _rational(right[1]) * dx >= 0
    wedge = z3.And(inner_left, inner_right) if angle <= math.pi else z3.Or(inner_left, inner_right)
    return z3.And(inside, wedge)


def solve(
    problem: Problem, geometry: MapGeometry, boxes: dict[Term, tuple[float, float]]
) -> tuple[str, dict[Term, float] | None]:
    """("sat", model) / ("unsat", None) / ("unknown", None); raises :class:`NotPolynomial`."""
    encoder = Encoder(problem.unknowns)
    z3 = encoder.z3
    solver = z3.Solver()
    solver.set("timeout", TIMEOUT_MS)
    for u, (low, high) in problem.ranges.items():
        if math.isfinite(low):
            solver.add(encoder(u) >= _rational(low))
        if math.isfinite(high):
            solver.add(encoder(u) <= _rational(high))
    for bound in problem.bounds:
        solver.add(_bound(encoder, bound, boxes, geometry))
    for condition in problem.conditions:
        solver.add(encoder(condition))
    for point in problem.points:
        solver.add(_region(encoder, point.region, encoder(point.x), encoder(point.y), point, geometry, boxes))
    solver.add(*encoder.side)
    verdict = solver.check()
    if verdict == z3.unsat:
        return "unsat", None
    if verdict != z3.sat:
        return "unknown", None
    model = solver.model()
    witness = {}
    for u, symbol in encoder.symbols.items():
        value = model.eval(symbol, model_completion=True)
        witness[u] = (
            float(value.as_fraction()) if z3.is_rational_value(value) else float(value.approx(20).as_fraction())
        )
    return "sat", witness


def _bound(encoder: Encoder, bound, boxes, geometry) -> object:
    z3 = encoder.z3
    value = encoder(bound.term)
    if not bound.angle:
        parts = []
        if math.isfinite(bound.lo):
            parts.append(value >= _rational(bound.lo))
        if math.isfinite(bound.hi):
            parts.append(value <= _rational(bound.hi))
        return z3.And(*parts) if parts else z3.BoolVal(True)
    from .branch_prune import BoxEvaluator
    from .intervals import Interval

    enclosure = BoxEvaluator(geometry, {u: Interval(*boxes[u]) for u in boxes}).num(bound.term)
    if enclosure is None:
        return z3.BoolVal(False)
    try:
        options = turns(enclosure.lo, enclosure.hi, bound)
    except NotLinear as error:
        raise NotPolynomial(str(error)) from None
    cases = [
        z3.And(value >= _rational(bound.lo + 2 * math.pi * k), value <= _rational(bound.hi + 2 * math.pi * k))
        for k in options
    ]
    return z3.Or(*cases) if cases else z3.BoolVal(False)


def is_polynomial(problem: Problem) -> bool:
    """Whether every term stays within polynomial arithmetic (regions are checked when encoding)."""
    seen: set[int] = set()
    stack = [b.term for b in problem.bounds] + list(problem.conditions)
    while stack:
        term = stack.pop()
        if id(term) in seen:
            continue
        seen.add(id(term))
        if term.op not in _POLYNOMIAL and term.op not in ("const", "var", "point"):
            return False
        stack.extend(term.args)
    return True
