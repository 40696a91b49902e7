"""Exact evaluation of a specialised problem at one assignment of its unknowns.

Used to verify witnesses: a candidate value for every unknown either meets
every constraint (bounds within tolerance, conditions true, random points
inside their regions) or it does not. Geometry goes through the same
:class:`~..geometry.MapGeometry` code as the vectorised path.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...model.geometry import normalize_angle
from ..geometry import MapGeometry
from ..terms import SCALAR_FUNCTIONS, Term
from .problem import Bound, Problem


class PointEvaluator:
    """Evaluates specialised terms for one assignment ``{unknown leaf: float}``."""

    def __init__(self, geometry: MapGeometry, assignment: dict[Term, float]):
        self.geometry = geometry
        self.assignment = assignment
        self.memo: dict[Term, Any] = {}

    def __call__(self, term: Term) -> Any:
        found = self.memo.get(term, self)
        if found is not self:
            return found
        result = self._compute(term)
        self.memo[term] = result
        return result

    def array(self, term: Term) -> np.ndarray:
        """The term's value as a one-element array (the geometry's calling convention)."""
        return np.array([self(term)])

    def _compute(self, term: Term) -> Any:
        if term.op == "const":
            return term.value
        if term in self.assignment:
            return self.assignment[term]
        if term.op == "pow":
            return self(term.args[0]) ** term.value
        if term.op in SCALAR_FUNCTIONS:
            try:
                return SCALAR_FUNCTIONS[term.op](*(self(a) for a in term.args))
            except (ValueError, ZeroDivisionError, OverflowError):
                return math.nan
        if term.op == "select":
            return self(term.args[1 + int(self(term.args[0]))])
        return self._geometry(term)

    def _geometry(self, term: Term) -> Any:
        args = [self.array(a) for a in term.args]
        g = self.geometry
        if term.op == "field":
            headings = g.field_values(term.value, args[0], args[1], self.array)[1]
            return float(headings[0]) if len(headings) else math.nan  # no value: no heading fits
        if term.op == "in_region":
            return bool(g.contains_points(term.value, args[0], args[1], self.array)[0])
        if term.op == "region_distance":
            return float(g.distances(term.value, args[0], args[1])[0])
        raise ValueError(f"cannot evaluate {term.op} at a point")


def bound_violation(value: float, bound: Bound) -> float:
    """How far a value lies outside a bound (0 inside; NaN is infinitely far); angles modulo 2π."""
    if math.isnan(value):
        return math.inf
    if bound.angle:
        middle, half = (bound.lo + bound.hi) / 2, (bound.hi - bound.lo) / 2
        return max(0.0, abs(float(normalize_angle(value - middle))) - half)
    return max(0.0, bound.lo - value, value - bound.hi)


def satisfies(problem: Problem, geometry: MapGeometry, assignment: dict[Term, float]) -> bool:
    """Whether the assignment meets every constraint of the problem exactly (bounds within their tolerance)."""
    ev = PointEvaluator(geometry, assignment)
    for variable, (low, high) in problem.ranges.items():
        if not low <= assignment[variable] <= high:
            return False
    for point in problem.points:
        inside = geometry.contains_points(point.region, ev.array(point.x), ev.array(point.y), ev.array)
        if not inside[0]:
            return False
    try:
        if any(bound_violation(ev(b.term), b) > 0 for b in problem.bounds):
            return False
        return all(bool(ev(c)) for c in problem.conditions)
    except (ValueError, ZeroDivisionError, OverflowError):
        return False
