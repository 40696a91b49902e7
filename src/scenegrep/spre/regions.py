"""Region sets: the values of spatial terms, for every evaluation context at once.

A term's value in one context (a sample, with its variable bindings) is a set of
regions (seed 004, Def. 5). :class:`Regions` holds the regions of *all* contexts in
flat columns, ``ctx`` naming each region's context, so every operation is one
vectorised call over the whole stream.

Semantics (scenegrep's default, the paper's): a region is a point set in the plane of
its space (image pixels or top-down metres). Boxes are *closed*; ``<interior>`` makes a
region open and ``<closure>`` closed again. Intersection is the point-set intersection
(touching closed boxes meet in a line, which is non-empty; open regions are kept as the
open part of their common interior), complement is taken within the sample's space
bounds, and ``<nonempty>`` tests for some point (a positive area for open regions).
Regions that are their own bounding box use a fast path on the bound columns; others
(oriented boxes, complements) are shapely geometries.

STREM's semantics (``--compat strem``, :func:`strem_intersection`): a term is a list of
the original boxes, and ``t & u`` lists both boxes of every pair whose axis-aligned boxes
overlap with positive area.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np
from ..lazy import lazy_import

from ..errors import UserError

shapely = lazy_import("shapely")


def pairs(left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All index pairs (i, j) with ``left[i] == right[j]`` (an equi-join), grouped by i."""
    order = np.argsort(right, kind="stable")
    keys = right[order]
    start = np.searchsorted(keys, left, side="left")
    count = np.searchsorted(keys, left, side="right") - start
    i = np.repeat(np.arange(len(left)), count)
    offsets = np.repeat(start - (np.cumsum(count) - count), count)
    j = order[offsets + np.arange(int(count.sum()))]
    return i, j


@dataclass(frozen=True, eq=False)
class Regions:
    """Regions of a term over all contexts; see the module docstring.

    ``x0 y0 x1 y1`` are bounds (NaN for an empty region); ``shape`` holds shapely geometries,
    or is None when every region equals its bounds box; ``src`` is the region's row in the
    space (-1 when derived by an operation); ``width``/``height`` the box's own size (bounds
    size when derived); ``oriented`` marks boxes given with a rotation.
    """

    ctx: np.ndarray
    x0: np.ndarray
    y0: np.ndarray
    x1: np.ndarray
    y1: np.ndarray
    shape: np.ndarray | None
    open: np.ndarray
    src: np.ndarray
    width: np.ndarray
    height: np.ndarray
    score: np.ndarray
    oriented: np.ndarray

    def __len__(self) -> int:
        return len(self.ctx)

    def take(self, rows: np.ndarray) -> Regions:
        return Regions(**{f.name: (None if (v := getattr(self, f.name)) is None else v[rows]) for f in fields(self)})

    def geometries(self) -> np.ndarray:
        """Shapely geometries of the regions (boxes made from their bounds)."""
        if self.shape is not None:
            return self.shape
        return shapely.box(self.x0, self.y0, self.x1, self.y1)

    def with_geometry(self, geometry: np.ndarray, open_: np.ndarray, score: np.ndarray, ctx: np.ndarray) -> Regions:
        """Derived regions of the given geometries (bounds and sizes recomputed, no source)."""
        bounds = shapely.bounds(geometry)
        return Regions(
            ctx,
            *bounds.T,
            geometry,
            open_,
            np.full(len(ctx), -1),
            bounds[:, 2] - bounds[:, 0],
            bounds[:, 3] - bounds[:, 1],
            score,
            np.zeros(len(ctx), bool),
        )

    # ------------------------------------------------------------------ predicates and measures
    def nonempty(self) -> np.ndarray:
        """Whether each region holds some point (an open one: a positive area)."""
        if self.shape is None:
            strict = (self.x0 < self.x1) & (self.y0 < self.y1)
            loose = (self.x0 <= self.x1) & (self.y0 <= self.y1)
            return np.where(self.open, strict, loose)
        return np.where(self.open, shapely.area(self.shape) > 0, ~shapely.is_empty(self.shape))

    def centre(self) -> tuple[np.ndarray, np.ndarray]:
        """Centroids (the box centre for boxes); NaN for empty regions."""
        if self.shape is None:
            empty = ~self.nonempty()
            return (np.where(empty, np.nan, (self.x0 + self.x1) / 2), np.where(empty, np.nan, (self.y0 + self.y1) / 2))
        centroids = shapely.centroid(self.shape)
        return shapely.get_x(centroids), shapely.get_y(centroids)

    def area(self) -> np.ndarray:
        if self.shape is None:
            return np.clip(self.x1 - self.x0, 0, None) * np.clip(self.y1 - self.y0, 0, None)
        return shapely.area(self.shape)


def concat(parts: list[Regions]) -> Regions:
    """The regions of all parts (the union of region sets: ``t | u``)."""
    shaped = any(p.shape is not None for p in parts)
    values = {}
    for f in fields(Regions):
        if f.name == "shape":
            values[f.name] = np.concatenate([p.geometries() for p in parts]) if shaped else None
        else:
            values[f.name] = np.concatenate([getattr(p, f.name) for p in parts])
    return Regions(**values)


def intersection(a: Regions, b: Regions) -> Regions:
    """``t & u``: the intersection of every pair of regions in the same context."""
    i, j = pairs(a.ctx, b.ctx)
    open_ = a.open[i] | b.open[j]
    score = np.minimum(a.score[i], b.score[j])
    if a.shape is None and b.shape is None:
        x0, y0 = np.maximum(a.x0[i], b.x0[j]), np.maximum(a.y0[i], b.y0[j])
        x1, y1 = np.minimum(a.x1[i], b.x1[j]), np.minimum(a.y1[i], b.y1[j])
        n = len(i)
        return Regions(
            a.ctx[i],
            x0,
            y0,
            x1,
            y1,
            None,
            open_,
            np.full(n, -1),
            np.clip(x1 - x0, 0, None),
            np.clip(y1 - y0, 0, None),
            score,
            np.zeros(n, bool),
        )
    geometry = shapely.intersection(a.geometries()[i], b.geometries()[j])
    return a.with_geometry(geometry, open_, score, a.ctx[i])


def complement(a: Regions, universe: np.ndarray) -> Regions:
    """``~t``: each region's complement within its context's space bounds (``universe``:
    one box geometry per context); closed regions become open and open ones closed."""
    geometry = shapely.difference(universe[a.ctx], a.geometries())
    return a.with_geometry(geometry, ~a.open, a.score, a.ctx)


def interior(a: Regions) -> Regions:
    return replace(a, open=np.ones(len(a), bool))


def closure(a: Regions) -> Regions:
    return replace(a, open=np.zeros(len(a), bool))


def subset_contexts(a: Regions, b: Regions) -> np.ndarray:
    """Context of each pair (A in a, B in b) where A is non-empty and a subset of B."""
    i, j = pairs(a.ctx, b.ctx)
    strict = ~a.open[i] & b.open[j]
    if a.shape is None and b.shape is None:
        covers = (b.x0[j] <= a.x0[i]) & (a.x1[i] <= b.x1[j]) & (b.y0[j] <= a.y0[i]) & (a.y1[i] <= b.y1[j])
        inside = (b.x0[j] < a.x0[i]) & (a.x1[i] < b.x1[j]) & (b.y0[j] < a.y0[i]) & (a.y1[i] < b.y1[j])
    else:
        ga, gb = a.geometries()[i], b.geometries()[j]
        covers, inside = shapely.covers(gb, ga), shapely.contains_properly(gb, ga)
    ok = a.nonempty()[i] & np.where(strict, inside, covers)
    return a.ctx[i][ok]


def strem_intersection(a: Regions, b: Regions) -> Regions:
    """STREM's ``t & u``: both original boxes of every pair whose axis-aligned boxes overlap
    with positive area; pairs with one oriented box give nothing (STREM: always empty)."""
    i, j = pairs(a.ctx, b.ctx)
    both = a.oriented[i] & b.oriented[j]
    if both.any():
        raise UserError("STREM v0.2.0 cannot intersect two oriented boxes (it panics); drop --compat strem")
    overlap = (
        (a.x0[i] < b.x1[j])
        & (b.x0[j] < a.x1[i])
        & (a.y0[i] < b.y1[j])
        & (b.y0[j] < a.y1[i])
        & ~a.oriented[i]
        & ~b.oriented[j]
    )
    return concat([a.take(i[overlap]), b.take(j[overlap])])
