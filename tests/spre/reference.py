"""Brute-force references for SpRE semantics, written independently of scenegrep's engine.

- Regular-expression layer: language membership of frames[i:j] by dynamic programming over
  the query tree; offline = greedy leftmost-longest non-overlapping non-empty matches;
  online = for each frame, the earliest start of a non-empty match ending there.
- Formula layer: plain loops over the boxes of each sample, with shapely polygons for the
  point-set semantics (default) or lists of the original boxes (STREM's semantics).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cache

import shapely

# ---------------------------------------------------------------------- queries
# A query is a nested tuple: ("letter", k) | ("any",) | ("cat", a, b) | ("alt", a, b)
# | ("rep", q, low, high or None) | ("empty",)


def membership(query: tuple, truth: list[list[bool]]):
    """A function (i, j) -> whether frames[i:j] is in the query's language; truth[f][k] is
    whether letter k holds in frame f."""

    @cache
    def member(node: tuple, i: int, j: int) -> bool:
        kind = node[0]
        if kind == "empty":
            return i == j
        if kind == "letter":
            return j == i + 1 and truth[i][node[1]]
        if kind == "any":
            return j == i + 1
        if kind == "cat":
            return any(member(node[1], i, k) and member(node[2], k, j) for k in range(i, j + 1))
        if kind == "alt":
            return member(node[1], i, j) or member(node[2], i, j)
        if kind == "rep":
            return repeat(node[1], node[2], node[3], i, j)
        raise ValueError(node)

    @cache
    def power(item: tuple, k: int, i: int, j: int) -> bool:
        """frames[i:j] is a concatenation of k words of the item's language."""
        if k == 0:
            return i == j
        return any(member(item, i, m) and power(item, k - 1, m, j) for m in range(i, j + 1))

    def repeat(item: tuple, low: int, high: int | None, i: int, j: int) -> bool:
        # beyond max(low, j - i) copies, some copies are empty and can be dropped
        top = max(low, j - i) if high is None else high
        return any(power(item, k, i, j) for k in range(low, top + 1))

    return member


def offline(query: tuple, truth: list[list[bool]]) -> list[tuple[int, int]]:
    member = membership(query, truth)
    n, out, position = len(truth), [], 0
    while position < n:
        found = None
        for i in range(position, n):
            ends = [j for j in range(i + 1, n + 1) if member(query, i, j)]
            if ends:
                found = (i, max(ends))
                break
        if found is None:
            break
        out.append(found)
        position = found[1]
    return out


def online(query: tuple, truth: list[list[bool]]) -> list[tuple[int, int]]:
    member = membership(query, truth)
    out = []
    for j in range(1, len(truth) + 1):
        starts = [i for i in range(j) if member(query, i, j)]
        if starts:
            out.append((min(starts), j))
    return out


def query_text(node: tuple, letters: list[str]) -> str:
    """The query in scenegrep's syntax, fully parenthesised."""
    kind = node[0]
    if kind == "letter":
        return f"[{letters[node[1]]}]"
    if kind == "any":
        return "."
    if kind == "cat":
        return f"({query_text(node[1], letters)}{query_text(node[2], letters)})"
    if kind == "alt":
        return f"({query_text(node[1], letters)}|{query_text(node[2], letters)})"
    if kind == "rep":
        low, high = node[2], node[3]
        bounds = f"{{{low},}}" if high is None else f"{{{low},{high}}}"
        return f"({query_text(node[1], letters)}){bounds}"
    raise ValueError(node)


# ---------------------------------------------------------------------- formulas
@dataclass(frozen=True)
class Box:
    category: str
    cx: float
    cy: float
    w: float
    h: float

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        return self.cx - self.w / 2, self.cy - self.h / 2, self.cx + self.w / 2, self.cy + self.h / 2

    def polygon(self) -> shapely.Geometry:
        """The closed box as a point set: a rectangle, or a segment or point when degenerate."""
        x0, y0, x1, y1 = self.bounds
        if self.w > 0 and self.h > 0:
            return shapely.box(x0, y0, x1, y1)
        if self.w > 0 or self.h > 0:
            return shapely.LineString([(x0, y0), (x1, y1)])
        return shapely.Point(x0, y0)


# A formula is a nested tuple:
#   ("class", name) | ("not", f) | ("and", f, g) | ("or", f, g) | ("ne", term) | ("cmp", op, m1, m2)
#   | ("E" | "A", ((var, name), ...), f)
# terms: ("class", name) | ("var", v) | ("inter", t, u) | ("union", t, u)
# metrics: ("num", c) | ("fn", name, term[, term]) | ("add" | "sub" | "mul", m1, m2)


def term_values(term: tuple, boxes: list[Box], env: dict[str, Box], strem: bool) -> list:
    """A term's regions: shapely geometries (default) or original boxes (STREM)."""
    kind = term[0]
    if kind == "class":
        found = [b for b in boxes if b.category == term[1]]
        return found if strem else [b.polygon() for b in found]
    if kind == "var":
        bound = [env[term[1]]] if term[1] in env else []
        return bound if strem else [b.polygon() for b in bound]
    left, right = term_values(term[1], boxes, env, strem), term_values(term[2], boxes, env, strem)
    if kind == "union":
        return left + right
    if strem:
        out = []
        for a, b in itertools.product(left, right):
            ax0, ay0, ax1, ay1 = a.bounds
            bx0, by0, bx1, by1 = b.bounds
            if ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1:
                out += [a, b]
        return out
    return [shapely.intersection(a, b) for a, b in itertools.product(left, right)]


def _centre(region, strem: bool) -> tuple[float, float]:
    if strem:
        return region.cx, region.cy
    if region.is_empty:
        return math.nan, math.nan
    c = region.centroid
    return c.x, c.y


def metric_values(metric: tuple, boxes: list[Box], env: dict[str, Box], strem: bool) -> list[float]:
    kind = metric[0]
    if kind == "num":
        return [metric[1]]
    if kind == "fn":
        name, args = metric[1], [term_values(t, boxes, env, strem) for t in metric[2:]]
        if name == "dist" and len(args) == 2:
            values = [math.dist(_centre(a, strem), _centre(b, strem)) for a, b in itertools.product(*args)]
        elif name in ("x", "y"):
            values = [_centre(a, strem)[0 if name == "x" else 1] for a in args[0]]
        elif name == "area":
            values = [a.w * a.h if strem else a.area for a in args[0]]
        else:
            values = [math.hypot(*_centre(a, strem)) for a in args[0]]
        return [v for v in values if not math.isnan(v)]
    left, right = metric_values(metric[1], boxes, env, strem), metric_values(metric[2], boxes, env, strem)
    op = {"add": float.__add__, "sub": float.__sub__, "mul": float.__mul__}[kind]
    return [op(float(a), float(b)) for a, b in itertools.product(left, right)]


def holds(formula: tuple, boxes: list[Box], env: dict[str, Box], strem: bool) -> bool:
    kind = formula[0]
    if kind == "class":
        return any(b.category == formula[1] for b in boxes)
    if kind == "not":
        return not holds(formula[1], boxes, env, strem)
    if kind == "and":
        return holds(formula[1], boxes, env, strem) and holds(formula[2], boxes, env, strem)
    if kind == "or":
        return holds(formula[1], boxes, env, strem) or holds(formula[2], boxes, env, strem)
    if kind == "ne":
        regions = term_values(formula[1], boxes, env, strem)
        return bool(regions) if strem else any(not r.is_empty for r in regions)
    if kind == "cmp":
        op = {"<": float.__lt__, ">": float.__gt__, "<=": float.__le__, ">=": float.__ge__}[formula[1]]
        left = metric_values(formula[2], boxes, env, strem)
        right = metric_values(formula[3], boxes, env, strem)
        return any(op(float(a), float(b)) for a, b in itertools.product(left, right))
    if kind in ("E", "A"):
        choices = [[b for b in boxes if b.category == name] for _, name in formula[1]]
        assignments = list(itertools.product(*choices))
        results = [
            holds(formula[2], boxes, {**env, **{v: b for (v, _), b in zip(formula[1], a)}}, strem) for a in assignments
        ]
        return any(results) if kind == "E" else bool(results) and all(results)
    raise ValueError(formula)


def formula_text(formula: tuple) -> str:
    """The formula in scenegrep's syntax (fully parenthesised; also valid for STREM where the
    constructs exist there)."""
    kind = formula[0]
    if kind == "class":
        return f"[:{formula[1]}:]"
    if kind == "not":
        return f"!({formula_text(formula[1])})"
    if kind in ("and", "or"):
        return f"({formula_text(formula[1])} {'&' if kind == 'and' else '|'} {formula_text(formula[2])})"
    if kind == "ne":
        return f"NE({term_text(formula[1])})"
    if kind == "cmp":
        return f"{metric_text(formula[2])} {formula[1]} {metric_text(formula[3])}"
    bindings = ", ".join(f"{v} := [:{name}:]" for v, name in formula[1])
    return f"{formula[0]}({bindings}) ({formula_text(formula[2])})"


def term_text(term: tuple) -> str:
    kind = term[0]
    if kind == "class":
        return f"[:{term[1]}:]"
    if kind == "var":
        return term[1]
    return f"({term_text(term[1])} {'&' if kind == 'inter' else '|'} {term_text(term[2])})"


def metric_text(metric: tuple) -> str:
    kind = metric[0]
    if kind == "num":
        return f"{metric[1]:.1f}"
    if kind == "fn":
        return f"@{metric[1]}({', '.join(term_text(t) for t in metric[2:])})"
    return f"({metric_text(metric[1])} {dict(add='+', sub='-', mul='*')[kind]} {metric_text(metric[2])})"
