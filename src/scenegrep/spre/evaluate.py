"""Evaluating spatial formulas over every sample of a space at once (seed 004, Defs. 5-7).

An evaluation runs over *contexts*: rows of (sample, variable bindings). The base
context is one row per sample; a quantifier ``E(v := [:c:]) phi`` expands each row into
one row per object of class c in its sample, evaluates phi on the expanded rows and
reduces back (some row true for E; every row true, and at least one, for A). Each node
of a formula is evaluated once, vectorised over all rows: terms give :class:`Regions`,
metric expressions give :class:`Values` (a list of numbers per row), formulas give one
boolean per row. Comparisons are existential over value pairs (an empty side is false),
relations over region pairs; arithmetic takes the cartesian product of its operands.

Nested quantifiers multiply the rows of a sample by the object count at each level, so before
evaluating, :meth:`Evaluator.frames` computes per sample, vectorised, the rows each quantifier
makes (the product of its classes' object counts over the enclosing levels) and refuses a frame
whose rows at some quantifier exceed :data:`MAX_ROWS_PER_FRAME` (:class:`TooManyRows`, naming
the quantifier and the frame). Within that limit it evaluates chunks of whole samples whose
estimated peak held cells (rows times bound variables, summed over the nested levels) stay
under :data:`CHUNK_CELLS`, so memory is bounded per chunk, whatever the trace's length; each
row's truth depends only on its sample, so chunked and whole evaluation agree.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from ..lazy import lazy_import

from ..errors import UserError
from . import regions as r
from . import syntax as s
from .space import Space

shapely = lazy_import("shapely")

MAX_ROWS_PER_FRAME = 100_000
"""Most evaluation rows (object combinations of nested quantifiers) in one frame."""
CHUNK_CELLS = 20_000_000
"""Peak held row cells (8 bytes each) one chunk of samples may need, about 160 MB."""


class TooManyRows(Exception):
    """A quantifier makes more than :data:`MAX_ROWS_PER_FRAME` rows in ``frame`` (a position
    in the space's frames)."""

    def __init__(self, quantifier: s.Quantifier, frame: int):
        super().__init__(f"nested quantifiers make more than {MAX_ROWS_PER_FRAME} object combinations in one frame")
        self.quantifier = quantifier
        self.frame = frame


@dataclass(frozen=True)
class Context:
    """Evaluation rows: the sample of each row and, per variable, its bound region row (-1: none)."""

    sample: np.ndarray
    bindings: dict[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.sample)

    def take(self, rows: np.ndarray) -> Context:
        return Context(self.sample[rows], {k: v[rows] for k, v in self.bindings.items()})


@dataclass(frozen=True)
class Values:
    """Numbers per context row: ``values[k]`` belongs to row ``ctx[k]``."""

    ctx: np.ndarray
    values: np.ndarray


def _any_per_row(ctx: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros(n, bool)
    out[ctx] = True
    return out


def _group(ctx: np.ndarray, values: np.ndarray, n: int, reduce: np.ufunc, empty: float) -> np.ndarray:
    out = np.full(n, empty)
    reduce.at(out, ctx, values)
    return out


class Evaluator:
    """Evaluates formulas on a space; ``strem`` selects STREM's term semantics."""

    def __init__(self, space: Space, strem: bool = False):
        self.space = space
        self.strem = strem
        self._class_rows: dict[s.ClassAtom, tuple[np.ndarray, np.ndarray]] = {}

    def base(self, bindings: dict[str, int] | None = None) -> Context:
        """One row per sample, with track variables bound to one object each."""
        fixed = {var: self.space.object_rows(obj) for var, obj in (bindings or {}).items()}
        return Context(np.arange(self.space.n_samples), fixed)

    def frames(self, formula: s.Formula, bindings: dict[str, int] | None = None) -> np.ndarray:
        """Truth of a formula in every frame: some sample of the frame satisfies it. Raises
        :class:`TooManyRows` before any work when a frame is over :data:`MAX_ROWS_PER_FRAME`;
        evaluates in chunks of samples of at most about :data:`CHUNK_CELLS` cells."""
        ctx = self.base(bindings)
        out = np.zeros(self.space.n_frames, bool)
        for rows in self._chunks(self._cells(formula, np.ones(self.space.n_samples), 1)):
            part = ctx.take(rows)
            out[self.space.sample_frame[part.sample[self.formula(formula, part)]]] = True
        return out

    def _cells(self, f: s.Formula, rows: np.ndarray, width: int) -> np.ndarray:
        """Per sample, the peak cells held evaluating ``f`` on ``rows`` rows per sample (float)
        of ``width`` cells each; raises :class:`TooManyRows` where a quantifier's rows per frame
        exceed the limit."""
        match f:
            case s.Not(operand):
                return self._cells(operand, rows, width)
            case s.And(left, right) | s.Or(left, right):
                return np.maximum(self._cells(left, rows, width), self._cells(right, rows, width))
            case s.Quantifier(_, bindings, body):
                inner = rows * np.prod([self._object_counts(b.atom) for b in bindings], axis=0)
                self._check_rows(f, inner)
                wider = width + len(bindings)
                return rows * width + inner * wider + self._cells(body, inner, wider)
        return rows * width

    def _object_counts(self, atom: s.ClassAtom) -> np.ndarray:
        """Per sample, how many objects of the class it has."""
        return np.bincount(self.class_rows(atom)[1], minlength=self.space.n_samples).astype(float)

    def _check_rows(self, q: s.Quantifier, rows: np.ndarray) -> None:
        """Raise :class:`TooManyRows` at the first frame whose samples hold more than
        :data:`MAX_ROWS_PER_FRAME` rows."""
        per_frame = np.bincount(self.space.sample_frame, weights=rows, minlength=self.space.n_frames)
        over = np.flatnonzero(~(per_frame <= MAX_ROWS_PER_FRAME))
        if len(over):
            raise TooManyRows(q, int(over[0]))

    @staticmethod
    def _chunks(cells: np.ndarray) -> list[np.ndarray]:
        """Consecutive sample ranges whose cells sum to at most :data:`CHUNK_CELLS` (a sample
        over it alone is its own chunk)."""
        chunk = np.floor(np.cumsum(cells) / CHUNK_CELLS).astype(np.int64)
        cuts = np.flatnonzero(np.diff(chunk)) + 1
        return np.split(np.arange(len(cells)), cuts)

    # ------------------------------------------------------------------ formulas
    def formula(self, f: s.Formula, ctx: Context) -> np.ndarray:
        match f:
            case s.Not(operand):
                return ~self.formula(operand, ctx)
            case s.And(left, right):
                return self.formula(left, ctx) & self.formula(right, ctx)
            case s.Or(left, right):
                return self.formula(left, ctx) | self.formula(right, ctx)
            case s.Quantifier():
                return self.quantifier(f, ctx)
            case s.Present(s.ClassAtom() as atom):
                return self._has_class(atom)[ctx.sample]
            case s.NonEmpty(s.ClassAtom() as atom) if self.strem or self.space.sizes_nonnegative:
                return self._has_class(atom)[ctx.sample]
            case s.Present(term) | s.NonEmpty(term):
                regions = self.term(term, ctx)
                return _any_per_row(regions.ctx[regions.nonempty()], len(ctx))
            case s.Subset(left, right):
                inner, outer = self._extent(left, ctx, "<subset>"), self._extent(right, ctx, "<subset>")
                return _any_per_row(r.subset_contexts(inner, outer), len(ctx))
            case s.Compare():
                return self.compare(f, ctx)
            case s.Relation():
                return self.relation(f, ctx)
        raise TypeError(f"not a formula: {f!r}")

    def quantifier(self, q: s.Quantifier, ctx: Context) -> np.ndarray:
        parent = np.arange(len(ctx))
        rows = ctx
        for binding in q.bindings:
            candidates, samples = self.class_rows(binding.atom)
            i, j = r.pairs(rows.sample, samples)
            rows = Context(rows.sample[i], {**{k: v[i] for k, v in rows.bindings.items()}, binding.var: candidates[j]})
            parent = parent[i]
        truth = self.formula(q.body, rows)
        if q.kind == "E":
            return _any_per_row(parent[truth], len(ctx))
        total = np.bincount(parent, minlength=len(ctx))
        good = np.bincount(parent[truth], minlength=len(ctx))
        return (total > 0) & (good == total)

    def compare(self, c: s.Compare, ctx: Context) -> np.ndarray:
        left, right = self.metric(c.left, ctx), self.metric(c.right, ctx)
        n = len(ctx)
        if c.op in ("==", "!="):
            lo_l, hi_l = (
                _group(left.ctx, left.values, n, np.minimum, np.inf),
                _group(left.ctx, left.values, n, np.maximum, -np.inf),
            )
            lo_r, hi_r = (
                _group(right.ctx, right.values, n, np.minimum, np.inf),
                _group(right.ctx, right.values, n, np.maximum, -np.inf),
            )
            both = np.isfinite(lo_l) & np.isfinite(lo_r)
            if c.op == "!=":
                return both & ~((lo_l == hi_l) & (lo_r == hi_r) & (lo_l == lo_r))
            i, j = r.pairs(left.ctx, right.ctx)
            return _any_per_row(left.ctx[i][left.values[i] == right.values[j]], n)
        if c.op in ("<", "<="):
            lo = _group(left.ctx, left.values, n, np.minimum, np.inf)
            hi = _group(right.ctx, right.values, n, np.maximum, -np.inf)
        else:
            lo = _group(right.ctx, right.values, n, np.minimum, np.inf)
            hi = _group(left.ctx, left.values, n, np.maximum, -np.inf)
        return (lo < hi) if c.op in ("<", ">") else (lo <= hi) & np.isfinite(lo) & np.isfinite(hi)

    def relation(self, rel: s.Relation, ctx: Context) -> np.ndarray:
        a = self.term(rel.left, ctx)
        if rel.right is None:
            if self.space.ego < 0:
                raise UserError(f"<{rel.name}>(...) with one argument is relative to the ego, and this trace has none")
            b = self.space.regions(*self._ego_rows(ctx))
        else:
            b = self.term(rel.right, ctx)
        i, j = r.pairs(a.ctx, b.ctx)
        ax, ay = a.centre()
        bx, by = b.centre()
        dx, dy = ax[i] - bx[j], ay[i] - by[j]
        if rel.name in ("leftof", "rightof", "frontof", "behind") and self.space.kind == "topdown":
            heading = np.where(b.src[j] >= 0, self.space.rotation[np.maximum(b.src[j], 0)], np.nan)
            forward = dx * -np.sin(heading) + dy * np.cos(heading)
            left = dx * -np.cos(heading) + dy * -np.sin(heading)
            test = {"frontof": forward > 0, "behind": forward < 0, "leftof": left > 0, "rightof": left < 0}[rel.name]
        elif rel.name in ("frontof", "behind"):
            raise UserError(f"<{rel.name}> needs headings: use the top-down space (image boxes have none)")
        else:
            test = {
                "leftof": dx < 0,
                "rightof": dx > 0,
                "above": dy < 0 if self.space.kind == "image" else dy > 0,
                "below": dy > 0 if self.space.kind == "image" else dy < 0,
            }[rel.name]
        return _any_per_row(a.ctx[i][test], len(ctx))

    def _ego_rows(self, ctx: Context) -> tuple[np.ndarray, np.ndarray]:
        ego = self.space.object_rows(self.space.ego)[ctx.sample]
        present = np.flatnonzero(ego >= 0)
        return ego[present], present

    def _has_class(self, atom: s.ClassAtom) -> np.ndarray:
        """Per sample, whether it has an object of the class (a class atom's truth: some such
        object is present; with non-negative sizes, also some non-empty region)."""
        return self.space.samples_having(self.space.matches(atom))

    # ------------------------------------------------------------------ terms
    def class_rows(self, atom: s.ClassAtom) -> tuple[np.ndarray, np.ndarray]:
        if atom not in self._class_rows:
            self._class_rows[atom] = self.space.rows_by_sample(self.space.matches(atom))
        return self._class_rows[atom]

    def term(self, t: s.Term, ctx: Context) -> r.Regions:
        match t:
            case s.ClassAtom():
                candidates, samples = self.class_rows(t)
                i, j = r.pairs(ctx.sample, samples)
                return self.space.regions(candidates[j], i)
            case s.Var(name):
                bound = ctx.bindings.get(name, np.full(len(ctx), -1))
                rows = np.flatnonzero(bound >= 0)
                return self.space.regions(bound[rows], rows)
            case s.Union(left, right):
                return r.concat([self.term(left, ctx), self.term(right, ctx)])
            case s.Intersection(left, right):
                combine = r.strem_intersection if self.strem else r.intersection
                return combine(self._extent(left, ctx, "an intersection"), self._extent(right, ctx, "an intersection"))
            case s.Complement(term):
                return r.complement(self._extent(term, ctx, "a complement"), self.space.universe[ctx.sample])
            case s.Interior(term):
                return r.interior(self._extent(term, ctx, "an interior"))
            case s.Closure(term):
                return r.closure(self._extent(term, ctx, "a closure"))
        raise TypeError(f"not a term: {t!r}")

    def _extent(self, t: s.Term, ctx: Context, what: str) -> r.Regions:
        """The regions of ``t``, whose extents ``what`` reads (:meth:`Space.check_extent`)."""
        regions = self.term(t, ctx)
        self.space.check_extent(regions, what)
        return regions

    # ------------------------------------------------------------------ metric expressions
    def metric(self, m: s.Metric, ctx: Context) -> Values:
        match m:
            case s.Number(value):
                return Values(np.arange(len(ctx)), np.full(len(ctx), value))
            case s.Negate(operand):
                inner = self.metric(operand, ctx)
                return Values(inner.ctx, -inner.values)
            case s.Arithmetic(op, left, right):
                a, b = self.metric(left, ctx), self.metric(right, ctx)
                i, j = r.pairs(a.ctx, b.ctx)
                with np.errstate(all="ignore"):
                    values = _ARITHMETIC[op](a.values[i], b.values[j])
                keep = np.isfinite(values)
                return Values(a.ctx[i][keep], values[keep])
            case s.Function():
                return self.function(m, ctx)
        raise TypeError(f"not a metric expression: {m!r}")

    def function(self, f: s.Function, ctx: Context) -> Values:
        args = [self.term(arg, ctx) for arg in f.args]
        name = {"w": "width", "h": "height"}.get(f.name, f.name)
        if name in EXTENT_FUNCTIONS:
            for arg in args:
                self.space.check_extent(arg, f"@{f.name}(...)")
        if len(args) == 2:
            a, b = args
            i, j = r.pairs(a.ctx, b.ctx)
            values = _PAIR_FUNCTIONS[name](a.take(i), b.take(j))
            ctx_of = a.ctx[i]
        else:
            values = self._unary(name, args[0])
            ctx_of = args[0].ctx
        keep = np.isfinite(values)
        return Values(ctx_of[keep], values[keep])

    def _unary(self, name: str, a: r.Regions) -> np.ndarray:
        if name in ("x", "y"):
            return a.centre()[0 if name == "x" else 1]
        if name == "dist":
            return np.hypot(*a.centre())
        if name in ("area", "width", "height", "score"):
            return a.area() if name == "area" else getattr(a, name)
        column = getattr(self.space, name)
        return np.where(a.src >= 0, column[np.maximum(a.src, 0)], np.nan)


def _distance(a: r.Regions, b: r.Regions) -> np.ndarray:
    (ax, ay), (bx, by) = a.centre(), b.centre()
    return np.hypot(ax - bx, ay - by)


def _gap(a: r.Regions, b: r.Regions) -> np.ndarray:
    if a.shape is None and b.shape is None:
        dx = np.maximum(0, np.maximum(a.x0 - b.x1, b.x0 - a.x1))
        dy = np.maximum(0, np.maximum(a.y0 - b.y1, b.y0 - a.y1))
        return np.hypot(dx, dy)
    return np.asarray(shapely.distance(a.geometries(), b.geometries()), dtype=float)


def _iou(a: r.Regions, b: r.Regions) -> np.ndarray:
    both = r.intersection(replace(a, ctx=np.arange(len(a))), replace(b, ctx=np.arange(len(b))))
    inter = np.zeros(len(a))
    inter[both.ctx] = both.area()
    union = a.area() + b.area() - inter
    with np.errstate(all="ignore"):
        return np.where(union > 0, inter / union, np.nan)


_PAIR_FUNCTIONS = {"dist": _distance, "gap": _gap, "iou": _iou}
EXTENT_FUNCTIONS = frozenset({"area", "width", "height", "gap", "iou"})
"""The functions that read their regions' extents (``dist``, ``x``, ``y`` read centres)."""
_ARITHMETIC = {"+": np.add, "-": np.subtract, "*": np.multiply, "/": np.divide, "^": np.power}
