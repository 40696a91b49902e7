"""δ-complete interval branch-and-prune (dReal's approach) for systems with trigonometry and
map lookups at unknown points.

The search space is a box: an interval for every scalar unknown (random variables,
random point coordinates). A box is *pruned* when interval evaluation proves some
constraint unsatisfiable anywhere in it — a bound's range misses its tolerance window,
a condition is false throughout, a random point's box misses its region — after
*contracting* it by propagating the bounds back through sums, differences and
products (HC4-revise). Surviving boxes are searched for a *witness*: a local
least-squares descent from the box's centre, accepted only if it satisfies every
constraint exactly (:mod:`.pointwise`). Otherwise the widest side is bisected.

The answer is ``sat`` with a witness, ``unsat`` when every box was pruned, or
``delta-sat`` when a box no wider than δ survives with no witness (the system is
satisfiable after relaxing by at most the box's extent: dReal's δ-sat), or
``undecided`` when the node budget runs out. Only ``unsat`` rejects a row, so the
procedure never loses a match (no false negatives); the last two are reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..geometry import MapGeometry
from ..terms import Term
from . import intervals as I
from .intervals import Interval
from .pointwise import PointEvaluator, bound_violation, satisfies
from .problem import Problem

FREE = Interval(-1e7, 1e7)
"""The range searched for an unbounded unknown (metres or radians): a scene spans far less."""

BOOL_TRUE, BOOL_FALSE, BOOL_EITHER = (True, False), (False, True), (True, True)


@dataclass
class Outcome:
    """``status`` is sat, delta-sat, unsat or undecided; ``witness`` assigns every unknown when sat;
    ``solver`` names the procedure that decided."""

    status: str
    witness: dict[Term, float] | None = None
    solver: str = "branch-and-prune"

    @property
    def feasible(self) -> bool:
        return self.status != "unsat"


class BoxEvaluator:
    """Interval values of specialised terms over a box ``{unknown: Interval}``."""

    def __init__(self, geometry: MapGeometry, box: dict[Term, Interval]):
        self.geometry = geometry
        self.box = box
        self.memo: dict[Term, object] = {}

    def num(self, term: Term) -> Interval | None:
        """An enclosure of the term's values (None: no real value exists in the box)."""
        return self._get(term)  # type: ignore[return-value]

    def truth(self, term: Term) -> tuple[bool, bool]:
        """(may be true, may be false) over the box."""
        return self._get(term)  # type: ignore[return-value]

    def _get(self, term: Term) -> object:
        if term in self.memo:
            return self.memo[term]
        result = self._compute(term)
        self.memo[term] = result
        return result

    def _compute(self, term: Term) -> object:
        op = term.op
        if op == "const":
            if term.kind == "bool":
                return BOOL_TRUE if term.value else BOOL_FALSE
            return Interval.point(term.value)
        if term in self.box:
            return self.box[term]
        if op in ("lt", "le", "eq", "ne"):
            return _compare(op, self.num(term.args[0]), self.num(term.args[1]))
        if op in ("and", "or", "not", "ite"):
            return self._logic(term)
        if op == "select":
            index = self.num(term.args[0])
            choices = [self.num(a) for a in term.args[1:]]
            return _hull([c for k, c in enumerate(choices) if index is not None and index.lo <= k <= index.hi])
        if op == "in_region":
            return self._in_region(term)
        args = [self.num(a) for a in term.args]
        if any(a is None for a in args):
            return None
        return _arithmetic(self, term, args)

    def _logic(self, term: Term) -> tuple[bool, bool]:
        parts = [self.truth(a) for a in term.args] if term.op != "ite" else None
        if term.op == "and":
            return parts[0][0] and parts[1][0], parts[0][1] or parts[1][1]
        if term.op == "or":
            return parts[0][0] or parts[1][0], parts[0][1] and parts[1][1]
        if term.op == "not":
            return parts[0][1], parts[0][0]
        raise ValueError("conditional values are not supported in the branch-and-prune solver")

    def _in_region(self, term: Term) -> tuple[bool, bool]:
        x, y = self.num(term.args[0]), self.num(term.args[1])
        if x is None or y is None:
            return BOOL_FALSE
        meets = self.geometry.boxes_meet(term.value, *_edges(x, y), _constant_values)
        if x.is_point and y.is_point:
            return (bool(meets[0]), not bool(meets[0]))
        return (bool(meets[0]), True)


def _edges(x: Interval, y: Interval) -> tuple[np.ndarray, ...]:
    return np.array([x.lo]), np.array([x.hi]), np.array([y.lo]), np.array([y.hi])


def _constant_values(term: Term) -> np.ndarray:
    """Region parameters of a specialised problem are constants."""
    if not term.is_const:
        raise ValueError("a region parameter depends on an unknown")
    return np.array([term.value])


def _hull(parts: list[Interval | None]) -> Interval | None:
    present = [p for p in parts if p is not None]
    if not present:
        return None
    return Interval(min(p.lo for p in present), max(p.hi for p in present))


def _compare(op: str, a: Interval | None, b: Interval | None) -> tuple[bool, bool]:
    if a is None or b is None:
        return BOOL_FALSE
    if op in ("lt", "le"):
        return a.lo <= b.hi, a.hi >= b.lo
    overlap = a.intersects(b)
    certain = a.is_point and b.is_point and a.lo == b.lo
    return (overlap, not certain) if op == "eq" else (not certain, overlap)


def _wrap(x: Interval) -> Interval:
    """Enclosure of the values wrapped into (-π, π] (the whole circle when it crosses ±π)."""
    if x.width >= 2 * math.pi:
        return Interval(-math.pi, math.pi)
    shift = I.normalize(x.lo) - x.lo
    lo, hi = x.lo + shift, x.hi + shift
    return Interval(lo, hi) if hi <= math.pi else Interval(-math.pi, math.pi)


def _arithmetic(ev: BoxEvaluator, term: Term, args: list[Interval]) -> Interval | None:
    op = term.op
    if op == "add":
        return args[0] + args[1]
    if op == "sub":
        return args[0] - args[1]
    if op == "mul":
        return args[0] * args[1]
    if op == "div":
        return args[0] / args[1] if not (args[1].lo == 0 == args[1].hi) else None
    if op == "neg":
        return -args[0]
    if op == "pow":
        return I.power(args[0], term.value)
    if op == "abs":
        return I.abs_(args[0])
    if op == "min":
        return I.minimum(args[0], args[1])
    if op == "max":
        return I.maximum(args[0], args[1])
    if op == "sqrt":
        return I.sqrt(args[0])
    if op == "sin":
        return I.sin(args[0])
    if op == "cos":
        return I.cos(args[0])
    if op == "heading_of":
        return I.atan2(-args[0], args[1])
    if op == "wrap":
        return _wrap(args[0])
    if op == "field":
        return _field(ev, term, args)
    if op == "region_distance":
        return _distance(ev, term, args)
    if op == "follow":
        return _follow(ev, term, args)
    raise ValueError(f"the branch-and-prune solver cannot evaluate {op}")


def _field(ev: BoxEvaluator, term: Term, args: list[Interval]) -> Interval | None:
    headings = ev.geometry.field_headings_in_box(
        term.value, args[0].lo, args[0].hi, args[1].lo, args[1].hi, _constant_values
    )
    return covering_arc(headings)


def _follow(ev: BoxEvaluator, term: Term, args: list[Interval]) -> Interval | None:
    from ..follow import follow_box

    key = ("follow", term.value[0], *term.args)
    if key not in ev.memo:
        ev.memo[key] = follow_box(ev.geometry, term.value[0], *args, _constant_values, covering_arc, I)  # type: ignore[index]
    end = ev.memo[key]  # type: ignore[index]
    return None if end is None else end[term.value[1]]


def covering_arc(headings: np.ndarray | None) -> Interval | None:
    """The shortest interval (unwrapped: it may reach past π) holding every heading modulo 2π;
    the whole circle for None (any heading), None for no heading at all."""
    if headings is None:
        return Interval(-math.pi, math.pi)
    if len(headings) == 0:
        return None
    angles = np.sort(np.mod(headings, 2 * math.pi))
    gaps = np.diff(np.concatenate([angles, [angles[0] + 2 * math.pi]]))
    widest = int(np.argmax(gaps))
    start = angles[(widest + 1) % len(angles)]
    width = max(0.0, 2 * math.pi - float(gaps[widest]))
    start = I.normalize(float(start))
    return Interval(math.nextafter(start, -math.inf), math.nextafter(start + width, math.inf))


def _distance(ev: BoxEvaluator, term: Term, args: list[Interval]) -> Interval:
    x, y = args
    corners_x = np.array([x.lo, x.hi, x.lo, x.hi])
    corners_y = np.array([y.lo, y.lo, y.hi, y.hi])
    far = ev.geometry.distances(term.value, corners_x, corners_y)
    half = math.hypot(x.width, y.width) / 2
    centre = ev.geometry.distances(term.value, np.array([(x.lo + x.hi) / 2]), np.array([(y.lo + y.hi) / 2]))[0]
    return Interval(max(0.0, centre - half), float(max(far.max(), centre + half)))


# ---------------------------------------------------------------------------- the search
class BranchAndPrune:
    """Decides one specialised problem; see the module docstring."""

    def __init__(
        self, problem: Problem, geometry: MapGeometry, delta: float, budget: int = 4000, witness_tries: int = 24
    ):
        self.problem = problem
        self.geometry = geometry
        self.delta = delta
        self.budget = budget
        self.witness_tries = witness_tries
        self.unknowns = problem.unknowns

    def initial_box(self) -> dict[Term, Interval] | None:
        box = {}
        for variable, (low, high) in self.problem.ranges.items():
            box[variable] = Interval(max(low, FREE.lo), min(high, FREE.hi)) if low <= high else None
        for point in self.problem.points:
            bounds = self.geometry.region_bounds(point.region, _constant_values)
            if bounds is None:
                return None
            box[point.x], box[point.y] = Interval(bounds[0], bounds[2]), Interval(bounds[1], bounds[3])
        return None if any(v is None for v in box.values()) else box

    def run(self) -> Outcome:
        box = self.initial_box()
        if box is None:
            return Outcome("unsat")
        stack = [box]
        nodes = tries = 0
        delta_box = None
        while stack:
            box = stack.pop()
            nodes += 1
            if nodes > self.budget:
                return Outcome("undecided")
            box = self.contract(box)
            if box is None or not self.possible(box):
                continue
            if tries < self.witness_tries:
                tries += 1
                found = self.local_witness(box)
                if found is not None:
                    return Outcome("sat", found)
            widest = max(self.unknowns, key=lambda u: box[u].width)
            if box[widest].width <= self.delta:
                delta_box = box
                continue
            low, high = box[widest].split()
            stack.extend(({**box, widest: high}, {**box, widest: low}))
        return Outcome("delta-sat") if delta_box is not None else Outcome("unsat")

    def possible(self, box: dict[Term, Interval]) -> bool:
        """Whether no constraint is proved unsatisfiable over the box."""
        ev = BoxEvaluator(self.geometry, box)
        for point in self.problem.points:
            if not self.geometry.boxes_meet(point.region, *_edges(box[point.x], box[point.y]), _constant_values)[0]:
                return False
        for bound in self.problem.bounds:
            value = ev.num(bound.term)
            if value is None or not _may_meet(value, bound):
                return False
        return all(ev.truth(c)[0] for c in self.problem.conditions)

    def contract(self, box: dict[Term, Interval]) -> dict[Term, Interval] | None:
        """HC4-revise over every bound, once: narrow unknowns the bounds pin through + - * /."""
        box = dict(box)
        for bound in self.problem.bounds:
            if bound.angle:
                continue
            ev = BoxEvaluator(self.geometry, box)
            target = Interval(max(bound.lo, -math.inf), min(bound.hi, math.inf))
            if not _narrow(ev, bound.term, target, box):
                return None
        return box

    def local_witness(self, box: dict[Term, Interval]) -> dict[Term, float] | None:
        """A least-squares descent on the constraint violations from the box centre, verified exactly."""
        from scipy.optimize import least_squares

        names = self.unknowns
        low = np.array([box[u].lo for u in names])
        high = np.array([box[u].hi for u in names])
        start = np.array([box[u].mid for u in names])
        if np.any(high - low <= 0):
            candidate = dict(zip(names, start.tolist()))
            return candidate if satisfies(self.problem, self.geometry, candidate) else None

        def residuals(values: np.ndarray) -> np.ndarray:
            ev = PointEvaluator(self.geometry, dict(zip(names, values.tolist())))
            out = []
            for bound in self.problem.bounds:
                try:
                    out.append(bound_violation(float(ev(bound.term)), bound))
                except (ValueError, ZeroDivisionError, OverflowError, IndexError):
                    out.append(1e6)
            for point in self.problem.points:
                out.append(_region_gap(self.geometry, point, ev))
            return np.minimum(np.array(out, dtype=float), 1e6)

        start = np.clip(start, low + 1e-12 * (high - low), high - 1e-12 * (high - low))
        try:
            fit = least_squares(residuals, start, bounds=(low, high), xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=200)
        except ValueError:
            return None
        candidate = dict(zip(names, fit.x.tolist()))
        return candidate if satisfies(self.problem, self.geometry, candidate) else None


def _region_gap(geometry: MapGeometry, point, ev: PointEvaluator) -> float:
    """Distance from a point's current value to its region (0 inside), as far as the region allows."""
    try:
        inside = geometry.contains_points(point.region, ev.array(point.x), ev.array(point.y), ev.array)[0]
    except ValueError:
        return 1.0
    if inside:
        return 0.0
    try:
        return float(geometry.distances(point.region, ev.array(point.x), ev.array(point.y))[0]) or 1e-9
    except Exception:  # regions without a distance (sectors, combinations) only say in or out
        return 1.0


def _may_meet(value: Interval, bound) -> bool:
    if bound.angle:
        middle, half = (bound.lo + bound.hi) / 2, (bound.hi - bound.lo) / 2
        return I.angle_may_be_within(value, middle, half)
    return value.hi >= bound.lo and value.lo <= bound.hi


def _narrow(ev: BoxEvaluator, term: Term, target: Interval, box: dict[Term, Interval]) -> bool:
    """Backward propagation of ``term in target`` into the box (False: infeasible)."""
    value = ev.num(term)
    if value is None:
        return False
    meet = value.intersection(target)
    if meet is None:
        return False
    if term in box:
        box[term] = meet
        return True
    op, args = term.op, term.args
    if op in ("add", "sub", "mul", "div", "neg"):
        parts = [ev.num(a) for a in args]
        if any(p is None for p in parts):
            return False
        for arg, narrowed in zip(args, _inverse(op, meet, parts)):
            if narrowed is False:
                return False
            if narrowed is not None and not _narrow(ev, arg, narrowed, box):
                return False
    return True


def _inverse(op: str, result: Interval, parts: list[Interval]) -> list[Interval | None | bool]:
    """For ``result = op(parts)``, enclosures each part must lie in (None: no information)."""
    if op == "neg":
        return [_meet(parts[0], -result)]
    a, b = parts
    if op == "add":
        return [_meet(a, result - b), _meet(b, result - a)]
    if op == "sub":
        return [_meet(a, result + b), _meet(b, a - result)]
    if op == "mul":
        return [
            _meet(a, result / b) if not b.contains(0) else None,
            _meet(b, result / a) if not a.contains(0) else None,
        ]
    return [_meet(a, result * b), None]


def _meet(current: Interval, narrowed: Interval) -> Interval | bool:
    found = current.intersection(narrowed)
    return False if found is None else found
