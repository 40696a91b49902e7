"""Exact decision, with a witness, of a row whose object follows ``roadDirection`` from a known
start for a random distance (``following roadDirection from X for D``, ``follow F from X for D``).

A row qualifies when every ``follow`` term of its system has the same constant start (x, y) and
the same distance D, an unknown with a finite range, over the lanes field (Scenic's
``roadDirection``). :func:`~..follow_pieces.follow_pieces` partitions D's range into pieces on
which the walk's end is ``start + D * a`` and the field at the end one heading (metres, radians).
On a piece every ``follow`` term is affine in D and the field at the end a constant, so:

* when D is the only unknown and every bound is affine in D (a heading bound constant), each
  bound is an interval of D, intersected over all bounds and pieces at once (numpy); the
  witness is the middle of the first non-empty interval;
* otherwise each piece, rewritten, goes to the general solvers (``solve_piece``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..follow import MAX_STEPS, STEP_M
from ..follow_pieces import Pieces, follow_pieces
from ..geometry import MapGeometry
from ..regions import MapField
from ..terms import Term, TermFactory
from .branch_prune import BoxEvaluator, Outcome
from .intervals import Interval
from .problem import Bound, Problem

ROAD_DIRECTION = MapField("lanes")
TWO_PI = 2 * math.pi


class NotSimple(Exception):
    """A term is not affine in the distance on a piece."""


@dataclass(frozen=True)
class Walk:
    """The one walk of a row: its start, distance unknown and the end's coordinate terms."""

    x: float
    y: float
    distance: Term
    ends: tuple[Term, ...]
    lo: float
    hi: float


def find_walk(problem: Problem) -> Walk | None:
    """The row's walk when it qualifies (see the module docstring), else None."""
    found = _follow_terms(problem)
    if not found:
        return None
    x, y, distance = found[0].args
    same = all(t.args == found[0].args and t.value[0] == ROAD_DIRECTION for t in found)
    if not same or not (x.is_const and y.is_const) or distance not in problem.scalars or problem.points:
        return None
    lo, hi = _distance_range(problem, distance)
    if not (math.isfinite(lo) and math.isfinite(hi)) or hi < lo or max(abs(lo), abs(hi)) > STEP_M * MAX_STEPS:
        return None
    ends = tuple(sorted(found, key=lambda t: t.value[1]))
    return Walk(float(x.value), float(y.value), distance, ends, lo, hi)


def _distance_range(problem: Problem, distance: Term) -> tuple[float, float]:
    """The distance's range, narrowed by bounds ``D - low >= 0`` and ``high - D >= 0`` whose other
    side depends on the other (bounded) variables only (``Range(d, 20)`` with ``d`` random)."""
    lo, hi = problem.ranges[distance]
    others = {u: Interval(*problem.ranges[u]) for u in problem.scalars if u is not distance}
    evaluator = BoxEvaluator(None, others)  # type: ignore[arg-type]
    for bound in problem.bounds:
        term = bound.term
        if term.op != "sub" or bound.lo != 0 or distance not in term.args or bound.hi != math.inf:
            continue
        side = term.args[1] if term.args[0] is distance else term.args[0]
        if distance in side.leaves() or not side.leaves() <= set(others):
            continue
        enclosure = evaluator.num(side)
        if enclosure is None:
            continue
        if term.args[0] is distance:
            lo = max(lo, enclosure.lo)
        else:
            hi = min(hi, enclosure.hi)
    return lo, hi


def _follow_terms(problem: Problem) -> list[Term]:
    found: dict[Term, None] = {}
    seen: set[Term] = set()
    stack = [b.term for b in problem.bounds] + list(problem.conditions)
    while stack:
        term = stack.pop()
        if term in seen:
            continue
        seen.add(term)
        if term.op == "follow":
            found[term] = None
        stack.extend(term.children())
    return list(found)


def walk_pieces(problems: list[Problem], walks: list[Walk | None], geometry: MapGeometry) -> dict[int, Pieces]:
    """The pieces of every row's walk (problem index -> pieces), enumerated together."""
    rows = [k for k, walk in enumerate(walks) if walk is not None]
    if not rows:
        return {}
    ranges = np.array([(walks[k].lo, walks[k].hi) for k in rows], dtype=float)  # type: ignore[union-attr]
    starts = np.array([(walks[k].x, walks[k].y) for k in rows], dtype=float)  # type: ignore[union-attr]
    target = np.array([end_box(problems[k], walks[k].ends) for k in rows], dtype=float)  # type: ignore[arg-type]
    pieces = follow_pieces(geometry, ROAD_DIRECTION, starts[:, 0], starts[:, 1], ranges[:, 0], ranges[:, 1], target)
    order = np.argsort(pieces.row, kind="stable")
    bounds = np.searchsorted(pieces.row[order], np.arange(len(rows) + 1))
    return {row: pieces.take(order[bounds[i] : bounds[i + 1]]) for i, row in enumerate(rows)}


def end_box(problem: Problem, ends: tuple[Term, ...]) -> tuple[float, float, float, float]:
    """The box (x_lo, x_hi, y_lo, y_hi) a walk's end (``ends``: its coordinate terms) must lie in by
    the bounds on its coordinates; infinite sides where there are none."""
    box = [-math.inf, math.inf, -math.inf, math.inf]
    for bound in problem.bounds:
        if bound.term in ends and not bound.angle:
            axis = bound.term.value[1]
            box[2 * axis] = max(box[2 * axis], bound.lo)
            box[2 * axis + 1] = min(box[2 * axis + 1], bound.hi)
    return box[0], box[1], box[2], box[3]


def only_end_box(problem: Problem, ends: tuple[Term, ...]) -> tuple[float, float, float, float] | None:
    """:func:`end_box` when it is finite and every bound of the row is on the end's coordinates or
    on the road direction there; else None."""
    if any(not (b.term in ends and not b.angle) and not is_end_heading(b.term, ends) for b in problem.bounds):
        return None
    box = end_box(problem, ends)
    return box if all(math.isfinite(v) for v in box) else None


def solve_walk(
    problem: Problem, walk: Walk, pieces: Pieces, solve_piece: Callable[[Problem, dict], Outcome]
) -> Outcome:
    """Decide the row over every piece of its walk (see the module docstring)."""
    if len(problem.scalars) == 1 and not problem.conditions:
        try:
            return _solve_intervals(problem, walk, pieces)
        except NotSimple:
            pass
    for k in range(len(pieces.row)):
        piece = _rewritten(problem, walk, pieces, k)
        outcome = solve_piece(piece, {u: piece.ranges[u] for u in piece.scalars})
        if outcome.feasible:
            return Outcome(outcome.status, outcome.witness, f"follow+{outcome.solver}")
    return Outcome("unsat", None, "follow")


def _solve_intervals(problem: Problem, walk: Walk, pieces: Pieces) -> Outcome:
    low, high = pieces.lo.copy(), pieces.hi.copy()
    memo: dict[Term, tuple[np.ndarray, np.ndarray]] = {}
    for bound in problem.bounds:
        const, slope = _form(bound.term, walk, pieces, memo)
        lo, hi = _bound_interval(bound, const, slope)
        low, high = np.maximum(low, lo), np.minimum(high, hi)
    feasible = np.flatnonzero(low <= high)
    if not len(feasible):
        return Outcome("unsat", None, "follow")
    k = feasible[0]
    return Outcome("sat", {walk.distance: float((low[k] + high[k]) / 2)}, "follow")


def _bound_interval(bound: Bound, const: np.ndarray, slope: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The D interval of each piece where ``lo <= const + slope * D <= hi`` (headings mod 2π)."""
    if bound.angle:
        if np.any(slope != 0):
            raise NotSimple("a heading that varies with the distance")
        inside = (bound.hi - bound.lo >= TWO_PI) | (np.mod(const - bound.lo, TWO_PI) <= bound.hi - bound.lo)
        return np.where(inside, -np.inf, np.inf), np.where(inside, np.inf, -np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        a, b = (bound.lo - const) / slope, (bound.hi - const) / slope
    flat = slope == 0
    inside = (bound.lo <= const) & (const <= bound.hi)
    lo = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(a, b))
    hi = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(a, b))
    return lo, hi


def _form(term: Term, walk: Walk, pieces: Pieces, memo: dict) -> tuple[np.ndarray, np.ndarray]:
    """(constant, slope) per piece of a term affine in D on every piece; raises NotSimple."""
    if term in memo:
        return memo[term]
    n = len(pieces.row)
    if term.op == "const" and term.kind == "num":
        result = (np.full(n, float(term.value)), np.zeros(n))
    elif term is walk.distance:
        result = (np.zeros(n), np.ones(n))
    elif term.op == "follow":
        axis = term.value[1]
        result = (np.full(n, walk.x if axis == 0 else walk.y), pieces.ax if axis == 0 else pieces.ay)
    elif is_end_heading(term, walk.ends):
        result = (pieces.heading, np.zeros(n))
    else:
        result = _form_op(term, [_form(a, walk, pieces, memo) for a in term.args])
    memo[term] = result
    return result


def _form_op(term: Term, args: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    op = term.op
    if op in ("add", "sub"):
        sign = 1.0 if op == "add" else -1.0
        return args[0][0] + sign * args[1][0], args[0][1] + sign * args[1][1]
    if op == "neg":
        return -args[0][0], -args[0][1]
    if op == "mul" and (not np.any(args[0][1]) or not np.any(args[1][1])):
        (ca, sa), (cb, sb) = args
        return ca * cb, ca * sb + sa * cb
    if op == "div" and not np.any(args[1][1]):
        return args[0][0] / args[1][0], args[0][1] / args[1][0]
    if op == "wrap" and not np.any(args[0][1]):
        return np.mod(args[0][0] + math.pi, TWO_PI) - math.pi, args[0][1]
    raise NotSimple(f"{op} of the distance")


def no_parameters(term: Term) -> np.ndarray:
    """The ``value`` argument of :func:`scenegrep.scene.follow.walk_end` for roadDirection, which has no
    parameters (a walk that asks for one is a bug)."""
    raise ValueError(f"roadDirection has no parameters, got {term!r}")


def is_end_heading(term: Term, ends: tuple[Term, ...]) -> bool:
    """Whether the term is the road direction at a walk's end (``ends``: its coordinate terms)."""
    return term.op == "field" and term.value == ROAD_DIRECTION and tuple(term.args) == ends[:2]


def _rewritten(problem: Problem, walk: Walk, pieces: Pieces, k: int) -> Problem:
    """The row's system on piece k: D in the piece, the walk's end affine in D, its heading constant."""
    f: TermFactory = problem.factory
    d = walk.distance
    start = (walk.x, walk.y)
    slope = (float(pieces.ax[k]), float(pieces.ay[k]))
    mapping: dict[Term, Term] = {}
    for end in walk.ends:
        axis = end.value[1]
        mapping[end] = f.op("add", f.const(start[axis]), f.op("mul", d, f.const(slope[axis])))
    heading = f.const(float(pieces.heading[k]))
    memo: dict[Term, Term] = {}

    def rewrite(term: Term) -> Term:
        if term in memo:
            return memo[term]
        if term in mapping:
            result = mapping[term]
        elif is_end_heading(term, walk.ends):
            result = heading
        elif not term.args:
            result = term
        else:
            result = f.op(term.op, *(rewrite(a) for a in term.args), value=term.value, kind=term.kind)
        memo[term] = result
        return result

    lo, hi = problem.ranges[d]
    ranges = {**problem.ranges, d: (max(lo, float(pieces.lo[k])), min(hi, float(pieces.hi[k])))}
    piece = Problem(f, list(problem.scalars), ranges, list(problem.points))
    piece.bounds = [Bound(rewrite(b.term), b.lo, b.hi, b.angle) for b in problem.bounds]
    piece.conditions = [rewrite(c) for c in problem.conditions]
    return piece
