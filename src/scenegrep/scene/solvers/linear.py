"""Linear programming for systems that are linear in the unknowns (HiGHS through SciPy).

A problem is linear when every bound term is affine in the unknowns, every
condition is a conjunction of comparisons of affine terms, and every random
point lies in a polygonal map region. Heading bounds hold modulo 2π: the few
multiples of 2π the term's range allows are tried one by one. A polygonal
region is not convex; it is cut (within the point's bounding box) into
triangles, and the point is tried in each: the region constraint becomes three
half-planes. Each combination is one LP feasibility problem; the system is
feasible when one of them is, which is exact (up to HiGHS's feasibility
tolerance of 1e-9, far below the feature tolerances).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import shapely

from ..geometry import MapGeometry
from ..terms import Term
from .problem import Bound, Problem

MAX_PIECES = 400
"""Triangles of a region tried before the problem is left to the branch-and-prune solver."""

MAX_TURNS = 7
"""Multiples of 2π tried for a heading bound before the problem is left to another solver."""


class NotLinear(Exception):
    """The problem is not linear in its unknowns."""


Form = tuple[float, dict[Term, float]]


def affine(term: Term, unknowns: set[Term], memo: dict[Term, Form] | None = None) -> Form:
    """``(constant, {unknown: coefficient})`` of a specialised term; raises :class:`NotLinear`."""
    memo = {} if memo is None else memo
    if term in memo:
        return memo[term]
    if term.op == "const" and term.kind == "num":
        result: Form = (float(term.value), {})
    elif term in unknowns:
        result = (0.0, {term: 1.0})
    elif term.op in ("add", "sub"):
        (ca, a), (cb, b) = (affine(x, unknowns, memo) for x in term.args)
        sign = 1.0 if term.op == "add" else -1.0
        coefs = dict(a)
        for u, c in b.items():
            coefs[u] = coefs.get(u, 0.0) + sign * c
        result = (ca + sign * cb, coefs)
    elif term.op == "neg":
        c, coefs = affine(term.args[0], unknowns, memo)
        result = (-c, {u: -v for u, v in coefs.items()})
    elif term.op in ("mul", "div"):
        (ca, a), (cb, b) = (affine(x, unknowns, memo) for x in term.args)
        if b and (a or term.op == "div"):
            raise NotLinear(term.op)
        if term.op == "div":
            result = (ca / cb, {u: v / cb for u, v in a.items()})
        elif a:
            result = (ca * cb, {u: v * cb for u, v in a.items()})
        else:
            result = (ca * cb, {u: v * ca for u, v in b.items()})
    else:
        raise NotLinear(term.op)
    memo[term] = result
    return result


def comparisons(term: Term, unknowns: set[Term], memo: dict[Term, Form]) -> list[tuple[Form, float]]:
    """A condition as ``form <= bound`` rows; raises :class:`NotLinear` for anything but a
    conjunction of (negated) comparisons, and for a constant false condition returns an infeasible row."""
    if term.op == "const" and term.kind == "bool":
        return [] if term.value else [((1.0, {}), 0.0)]
    if term.op == "and":
        return [row for part in term.args for row in comparisons(part, unknowns, memo)]
    negated = term.op == "not"
    inner = term.args[0] if negated else term
    if inner.op not in ("lt", "le"):
        raise NotLinear(inner.op)
    (ca, a), (cb, b) = (affine(x, unknowns, memo) for x in inner.args)
    left, right = ((cb, b), (ca, a)) if negated else ((ca, a), (cb, b))
    coefs = dict(left[1])
    for u, c in right[1].items():
        coefs[u] = coefs.get(u, 0.0) - c
    return [((left[0] - right[0], coefs), 0.0)]


def is_linear(problem: Problem, geometry: MapGeometry) -> bool:
    unknowns = set(problem.unknowns)
    memo: dict[Term, Form] = {}
    try:
        for bound in problem.bounds:
            affine(bound.term, unknowns, memo)
        for condition in problem.conditions:
            comparisons(condition, unknowns, memo)
    except (NotLinear, ZeroDivisionError):
        return False
    return all(geometry.static_geometry(p.region) is not None for p in problem.points)


def solve(problem: Problem, geometry: MapGeometry, boxes: dict[Term, tuple[float, float]]) -> dict[Term, float] | None:
    """A feasible assignment of a linear problem, or None when there is none.

    ``boxes`` bounds every unknown (from interval contraction); random points are cut into
    triangles within it.
    """
    from scipy.optimize import linprog

    unknowns = problem.unknowns
    index = {u: i for i, u in enumerate(unknowns)}
    memo: dict[Term, Form] = {}
    rows, limits = _rows(problem, set(unknowns), memo, index)
    angle_options = [_turns(b, affine(b.term, set(unknowns), memo), boxes) for b in problem.bounds if b.angle]
    angle_bounds = [b for b in problem.bounds if b.angle]
    pieces = [triangles(p.region, boxes[p.x], boxes[p.y], geometry) for p in problem.points]
    bounds = [(max(boxes[u][0], -1e9), min(boxes[u][1], 1e9)) for u in unknowns]
    for turns in itertools.product(*angle_options):
        angle_rows, angle_limits = _angle_rows(angle_bounds, turns, memo, index, set(unknowns))
        for chosen in itertools.product(*pieces):
            region_rows, region_limits = _triangle_rows(problem, chosen, index)
            a_ub = np.array(rows + angle_rows + region_rows, dtype=float).reshape(-1, len(unknowns))
            b_ub = np.array(limits + angle_limits + region_limits, dtype=float)
            result = linprog(
                np.zeros(len(unknowns)),
                A_ub=a_ub if len(a_ub) else None,
                b_ub=b_ub if len(b_ub) else None,
                bounds=bounds,
                method="highs",
            )
            if result.status == 0:
                return dict(zip(unknowns, result.x.tolist()))
    return None


def _row(form: Form, index: dict[Term, int], sign: float) -> list[float]:
    row = [0.0] * len(index)
    for u, c in form[1].items():
        row[index[u]] = sign * c
    return row


def _rows(problem: Problem, unknowns: set[Term], memo: dict, index: dict[Term, int]) -> tuple[list, list]:
    rows, limits = [], []
    for bound in problem.bounds:
        if bound.angle:
            continue
        form = affine(bound.term, unknowns, memo)
        if math.isfinite(bound.hi):
            rows.append(_row(form, index, 1.0))
            limits.append(bound.hi - form[0])
        if math.isfinite(bound.lo):
            rows.append(_row(form, index, -1.0))
            limits.append(form[0] - bound.lo)
    for condition in problem.conditions:
        for form, limit in comparisons(condition, unknowns, memo):
            rows.append(_row(form, index, 1.0))
            limits.append(limit - form[0])
    return rows, limits


def turns(low: float, high: float, bound: Bound) -> list[int]:
    """Multiples of 2π that can bring a term ranging over [low, high] onto an angle bound's window,
    nearest to the range's centre first; raises :class:`NotLinear` beyond :data:`MAX_TURNS` of them
    (a term that free can take any heading; the other solvers handle it)."""
    if not (math.isfinite(low) and math.isfinite(high)):
        raise NotLinear("unbounded heading")
    first = math.floor((low - bound.hi) / (2 * math.pi))
    last = math.ceil((high - bound.lo) / (2 * math.pi))
    if last - first + 1 > MAX_TURNS:
        raise NotLinear("a heading that can wind around many times")
    centre = ((low + high) / 2 - (bound.lo + bound.hi) / 2) / (2 * math.pi)
    return sorted(range(first, last + 1), key=lambda k: abs(k - centre))


def _turns(bound: Bound, form: Form, boxes: dict[Term, tuple[float, float]]) -> list[int]:
    low = high = form[0]
    for u, c in form[1].items():
        a, b = c * boxes[u][0], c * boxes[u][1]
        low, high = low + min(a, b), high + max(a, b)
    return turns(low, high, bound)


def _angle_rows(
    bounds: list[Bound], turns: tuple[int, ...], memo: dict, index: dict, unknowns: set
) -> tuple[list, list]:
    rows, limits = [], []
    for bound, k in zip(bounds, turns):
        form = affine(bound.term, unknowns, memo)
        shift = 2 * math.pi * k
        rows += [_row(form, index, 1.0), _row(form, index, -1.0)]
        limits += [bound.hi + shift - form[0], form[0] - bound.lo - shift]
    return rows, limits


def triangles(region_value, x_range, y_range, geometry: MapGeometry) -> list[np.ndarray]:
    """Triangles (3 x 2 vertex arrays) covering a map-layer region inside the box x_range x y_range."""
    region = geometry.static_geometry(region_value)
    if region is None:
        raise NotLinear("the region is not made of known map layers")
    (x0, x1), (y0, y1) = x_range, y_range
    window = shapely.box(max(x0, -1e7), max(y0, -1e7), min(x1, 1e7), min(y1, 1e7))
    part = shapely.intersection(region, window)
    if part.is_empty:
        return []
    parts = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.get_parts(part)))
    if len(parts) > MAX_PIECES:
        raise NotLinear("too many pieces")
    found = [shapely.get_coordinates(t)[:3] for t in parts if t.area > 0]
    if not found:
        raise NotLinear("the region has no area inside the point's box")
    return found


def _triangle_rows(problem: Problem, triangles: tuple[np.ndarray, ...], index: dict[Term, int]) -> tuple[list, list]:
    """Half-plane rows keeping each point inside its triangle (either orientation)."""
    rows, limits = [], []
    for point, triangle in zip(problem.points, triangles):
        (ax, ay), (bx, by), (cx, cy) = triangle
        orientation = 1.0 if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) >= 0 else -1.0
        for (px, py), (qx, qy) in (((ax, ay), (bx, by)), ((bx, by), (cx, cy)), ((cx, cy), (ax, ay))):
            # inside: orientation * cross(q - p, r - p) >= 0 for the point r
            row = [0.0] * len(index)
            row[index[point.x]] = orientation * (qy - py)
            row[index[point.y]] = -orientation * (qx - px)
            rows.append(row)
            limits.append(orientation * ((qy - py) * px - (qx - px) * py))
    return rows, limits
