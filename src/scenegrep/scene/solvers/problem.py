"""One row's constraint system, specialised: every term not involving the unknowns is a constant.

:func:`build` reads one (expanded) row of an :class:`~..evaluate.Evaluator`:
feature constraints become ``lo <= term <= hi`` bounds (headings modulo 2π),
requirements become boolean conditions, random variables get their ranges and
random points their regions. The solvers work on this small system alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, is_dataclass, replace
from typing import Any

from ..tolerance import Tolerance
from ..dependencies import Group
from ..evaluate import Evaluator
from ..regions import Field, Region
from ..terms import RandomPoint, Term, TermFactory


@dataclass
class Bound:
    """``lo <= term <= hi``; for an angle, modulo 2π."""

    term: Term
    lo: float
    hi: float
    angle: bool = False


@dataclass
class PointUnknown:
    """A random point: its coordinate leaves and (specialised) region."""

    point: RandomPoint
    x: Term
    y: Term
    region: Region


@dataclass
class Problem:
    """The unknowns of one row and the constraints they must meet."""

    factory: TermFactory
    scalars: list[Term] = field(default_factory=list)
    ranges: dict[Term, tuple[float, float]] = field(default_factory=dict)
    points: list[PointUnknown] = field(default_factory=list)
    bounds: list[Bound] = field(default_factory=list)
    conditions: list[Term] = field(default_factory=list)

    @property
    def unknowns(self) -> list[Term]:
        """Every scalar unknown: variables, then point coordinates."""
        return self.scalars + [c for p in self.points for c in (p.x, p.y)]


class Specialiser:
    """Rewrites terms of one evaluator row with its known values folded to constants."""

    def __init__(self, ev: Evaluator, row: int, factory: TermFactory):
        self.ev = ev
        self.row = row
        self.f = factory
        self.memo: dict[Term, Term] = {}

    def term(self, term: Term) -> Term:
        found = self.memo.get(term)
        if found is not None:
            return found
        if term in self.ev.unknowns:
            result = term
        elif not self.ev.depends_on_unknowns(term):
            value = self.ev.value(term)[self.row]
            result = self.f.const(value.item() if hasattr(value, "item") else value)
        else:
            args = tuple(self.term(a) for a in term.args)
            result = self.f.op(term.op, *args, value=self.value(term.value), kind=term.kind)
        self.memo[term] = result
        return result

    def value(self, value: Any) -> Any:
        """A node value (region, field, or tuple of them) with its terms specialised."""
        if isinstance(value, tuple):
            return tuple(self.value(v) for v in value)
        if isinstance(value, (Region, Field)) and is_dataclass(value):
            changes = {}
            for f in fields(value):
                item = getattr(value, f.name)
                if isinstance(item, Term):
                    changes[f.name] = self.term(item)
                elif isinstance(item, tuple):
                    changes[f.name] = tuple(self.value(v) for v in item)
                elif isinstance(item, (Region, Field)):
                    changes[f.name] = self.value(item)
            return replace(value, **changes) if changes else value
        return value


def build(ev: Evaluator, group: Group, tolerance: Tolerance, row: int) -> Problem:
    """The specialised system of row ``row`` of the evaluator's current rows."""
    problem = Problem(TermFactory())
    s = Specialiser(ev, row, problem.factory)
    for feature in group.features:
        observed = float(ev.value(feature.observed)[row])
        tol = tolerance.of(feature)
        problem.bounds.append(Bound(s.term(feature.term), observed - tol, observed + tol, feature.is_angle))
    for requirement in group.requirements:
        problem.conditions.append(s.term(requirement.condition))
    points: dict[RandomPoint, dict[int, Term]] = {}
    for u in sorted(ev.unknowns, key=repr):
        if u.op == "point":
            points.setdefault(u.value[0], {})[u.value[1]] = u
            continue
        problem.scalars.append(u)
        low, high = s.term(u.value.low), s.term(u.value.high)
        problem.ranges[u] = (_number(low, -math.inf), _number(high, math.inf))
        if not low.is_const:
            problem.bounds.append(Bound(problem.factory.op("sub", u, low), 0.0, math.inf))
        if not high.is_const:
            problem.bounds.append(Bound(problem.factory.op("sub", high, u), 0.0, math.inf))
    for point, axes in points.items():
        problem.points.append(PointUnknown(point, axes[0], axes[1], s.value(point.region)))
    return problem


def _number(term: Term, default: float) -> float:
    return float(term.value) if term.is_const else default
