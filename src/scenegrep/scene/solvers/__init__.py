"""Feasibility solvers for the conditioned constraint systems of a scene query, row by row.

:func:`decide_rows` builds each row's specialised system (:mod:`.problem`) and
:func:`solve` decides it:

1. interval contraction bounds every unknown (and may already refute the row);
2. a random point on a curb is split into pieces, one per curb segment near it:
   on a segment the point is ``start + t * (end - start)`` with ``t`` in [0, 1] and
   the curb's direction there is the segment's heading, a constant (the paper's
   Fig. 6 ``spot`` becomes linear this way);
3. each piece goes to the first solver that applies: linear programming when it is
   linear (:mod:`.linear`), z3 when it is polynomial (:mod:`.smt`), otherwise
   interval branch-and-prune (:mod:`.branch_prune`), which also takes over when
   z3 times out.

A row that follows ``roadDirection`` from a known start for a random distance skips these
steps: :mod:`.walk` decides it exactly over the pieces of the walk, with a witness; one that
follows it from a random start (a point on a curb or of a region, a vector of ranges) goes first
to :mod:`.walk_inverse` (the walk inverted, exact with a witness; its preimages, too, enumerated
for all rows at once), a curb start then to :mod:`.walk_start` (forward over (s, D) regions), and
to these steps only where those leave it undecided.

The row is feasible when one piece is. Solver verdicts other than a proof of
infeasibility keep the row (soundness first); ``delta-sat`` and ``undecided``
verdicts are counted (in the evaluator's ``notes``) so the caller can report them.
"""

from __future__ import annotations


import numpy as np
import shapely

from ..tolerance import Tolerance
from ..dependencies import Group
from ..evaluate import Evaluator
from ..geometry import MapGeometry
from ..regions import Intersection, MapField, MapRegion, Region
from ..terms import RandomVariable, Term, TermFactory
from . import linear, smt
from .branch_prune import BranchAndPrune, Outcome
from .pointwise import satisfies
from .problem import Bound, PointUnknown, Problem, build
from ..follow_inverse import Preimage
from ..follow_pieces import Pieces
from .walk import Walk, find_walk, solve_walk, walk_pieces
from .walk_inverse import StartWalk, find_start_walk, solve_start_walk, start_preimages
from .walk_start import find_curb_walk, solve_curb_walk


def decide_rows(ev: Evaluator, group: Group, tolerance: Tolerance) -> np.ndarray:
    """Feasibility of every current row of the evaluator, one specialised system at a time (the
    walks of rows that follow the road direction are enumerated for all rows at once)."""
    ok = np.zeros(ev.size, dtype=bool)
    problems = [build(ev, group, tolerance, row) for row in range(ev.size)]
    walks = [find_walk(problem) if problem.unknowns else None for problem in problems]
    pieces = walk_pieces(problems, walks, ev.geometry)
    starts = [find_start_walk(p) if p.unknowns and w is None else None for p, w in zip(problems, walks)]
    inverted = start_preimages(problems, starts, ev.geometry)
    for row, problem in enumerate(problems):
        start = (starts[row], *inverted[row]) if row in inverted else None
        outcome = solve(problem, ev.geometry, tolerance, walks[row], pieces.get(row), start)
        ev.notes[f"{outcome.solver}:{outcome.status}"] += 1
        ok[row] = outcome.feasible
    return ok


def solve(
    problem: Problem,
    geometry: MapGeometry,
    tolerance: Tolerance,
    walk: Walk | None = None,
    pieces: Pieces | None = None,
    start: tuple[StartWalk, Preimage, shapely.Geometry] | None = None,
) -> Outcome:
    """Decide one specialised system (see the module docstring); ``walk`` and ``pieces`` are the
    row's walk and its pieces when already found, ``start`` its random-start walk, preimage and
    start domain (:func:`.walk_inverse.start_preimages`)."""
    if not problem.unknowns:
        return Outcome("sat", {}, "direct") if satisfies(problem, geometry, {}) else Outcome("unsat", None, "direct")
    delta = max(tolerance.position, tolerance.heading)
    walk = walk or find_walk(problem)
    if walk is not None:
        pieces = pieces or walk_pieces([problem], [walk], geometry)[0]
        return solve_walk(problem, walk, pieces, lambda piece, boxes: _solve_piece(piece, geometry, boxes, delta))
    if start is None:
        found = find_start_walk(problem)
        inverted = start_preimages([problem], [found], geometry) if found is not None else {}
        start = (found, *inverted[0]) if 0 in inverted else None  # type: ignore[assignment]
    if start is not None:
        outcome = solve_start_walk(problem, start[0], geometry, start[1], start[2])
        if outcome.status != "undecided":
            return outcome
    curb_walk = find_curb_walk(problem)
    if curb_walk is not None:
        outcome = solve_curb_walk(problem, curb_walk, geometry)
        if outcome.status != "undecided":
            return outcome
    search = BranchAndPrune(problem, geometry, delta)
    box = search.initial_box()
    box = None if box is None else search.contract(box)
    if box is None or not search.possible(box):
        return Outcome("unsat", None, "contraction")
    boxes = {u: (iv.lo, iv.hi) for u, iv in box.items()}
    for piece, piece_boxes, complete in _pieces(problem, geometry, boxes):
        outcome = _solve_piece(piece, geometry, piece_boxes, delta)
        if outcome.feasible:
            if outcome.witness is not None:
                complete(outcome.witness)
            return outcome
    return Outcome("unsat", None, "pieces")


def _solve_piece(
    problem: Problem, geometry: MapGeometry, boxes: dict[Term, tuple[float, float]], delta: float
) -> Outcome:
    if linear.is_linear(problem, geometry):
        try:
            witness = linear.solve(problem, geometry, boxes)
            return Outcome("sat" if witness is not None else "unsat", witness, "linear")
        except linear.NotLinear:
            pass
    if smt.is_polynomial(problem):
        try:
            verdict, witness = smt.solve(problem, geometry, boxes)
            if verdict in ("sat", "unsat"):
                return Outcome(verdict, witness, "smt")
        except smt.NotPolynomial:
            pass
    return BranchAndPrune(problem, geometry, delta).run()


# ---------------------------------------------------------------------------- curb pieces
def _on_curb(region: Region) -> bool:
    if isinstance(region, MapRegion):
        return region.layer == "curb"
    return isinstance(region, Intersection) and any(_on_curb(p) for p in region.parts)


def _rest_of(region: Region) -> list[Region]:
    """The parts of an intersection other than the curb."""
    if isinstance(region, Intersection):
        return [p for part in region.parts for p in _rest_of(part)]
    return [] if isinstance(region, MapRegion) and region.layer == "curb" else [region]


def _pieces(problem: Problem, geometry: MapGeometry, boxes: dict[Term, tuple[float, float]]):
    """(piece, its boxes, a function completing a piece's witness): the problem itself, or one piece
    per curb segment near its first curb point."""
    point = next((p for p in problem.points if _on_curb(p.region)), None)
    if point is None:
        yield problem, boxes, lambda witness: None
        return
    curbs = geometry.map.curb_polylines if geometry.map is not None else None
    if curbs is None or not len(curbs):
        return
    (x0, x1), (y0, y1) = boxes[point.x], boxes[point.y]
    start, end = curbs.start, curbs.end
    near = (
        (np.minimum(start[:, 0], end[:, 0]) <= x1)
        & (np.maximum(start[:, 0], end[:, 0]) >= x0)
        & (np.minimum(start[:, 1], end[:, 1]) <= y1)
        & (np.maximum(start[:, 1], end[:, 1]) >= y0)
    )
    for k in np.flatnonzero(near).tolist():
        span = _clip_segment(start[k], end[k], (x0, x1, y0, y1))
        if span is not None:
            yield _on_segment(problem, point, start[k], end[k], float(curbs.heading[k]), span, boxes)


def _clip_segment(a: np.ndarray, b: np.ndarray, box: tuple[float, float, float, float]) -> tuple[float, float] | None:
    """The parameter range [t0, t1] of a + t (b - a) inside the box (Liang-Barsky)."""
    t0, t1 = 0.0, 1.0
    d = b - a
    for axis, (low, high) in enumerate(((box[0], box[1]), (box[2], box[3]))):
        if d[axis] == 0:
            if not low <= a[axis] <= high:
                return None
            continue
        u, v = sorted(((low - a[axis]) / d[axis], (high - a[axis]) / d[axis]))
        t0, t1 = max(t0, u), min(t1, v)
    return (t0, t1) if t0 <= t1 else None


def _on_segment(problem: Problem, point: PointUnknown, a, b, heading: float, span, boxes):
    """The problem with the point on segment a-b at parameter t and the curb's direction fixed there."""
    f: TermFactory = problem.factory
    t = f.var(RandomVariable(f"{point.point.name} along a curb segment", f.const(span[0]), f.const(span[1])))
    x = f.op("add", f.const(float(a[0])), f.op("mul", t, f.const(float(b[0] - a[0]))))
    y = f.op("add", f.const(float(a[1])), f.op("mul", t, f.const(float(b[1] - a[1]))))
    rewrite = _Rewriter(f, {point.x: x, point.y: y}, (point.x, point.y), heading)
    piece = Problem(
        f, problem.scalars + [t], {**problem.ranges, t: span}, [p for p in problem.points if p is not point]
    )
    piece.bounds = [Bound(rewrite(b.term), b.lo, b.hi, b.angle) for b in problem.bounds]
    piece.conditions = [rewrite(c) for c in problem.conditions]
    piece.conditions += [f.op("in_region", x, y, value=region, kind="bool") for region in _rest_of(point.region)]
    piece_boxes = {u: v for u, v in boxes.items() if u not in (point.x, point.y)}
    piece_boxes[t] = span

    def complete(witness: dict[Term, float]) -> None:
        """Put the point's coordinates in a witness of the piece (which knows only ``t``)."""
        along = witness.pop(t)
        witness[point.x] = float(a[0] + along * (b[0] - a[0]))
        witness[point.y] = float(a[1] + along * (b[1] - a[1]))

    return piece, piece_boxes, complete


class _Rewriter:
    """Substitutes a point's coordinates, and the curb direction at that point by a constant."""

    def __init__(self, factory: TermFactory, mapping: dict[Term, Term], leaves: tuple[Term, Term], heading: float):
        self.f = factory
        self.mapping = mapping
        self.leaves = leaves
        self.heading = heading
        self.memo: dict[Term, Term] = {}

    def __call__(self, term: Term) -> Term:
        if term in self.memo:
            return self.memo[term]
        if term in self.mapping:
            result = self.mapping[term]
        elif term.op == "field" and term.value == MapField("curb") and tuple(term.args) == self.leaves:
            result = self.f.const(self.heading)
        elif not term.args:
            result = term
        else:
            result = self.f.op(term.op, *(self(a) for a in term.args), value=term.value, kind=term.kind)
        self.memo[term] = result
        return result
