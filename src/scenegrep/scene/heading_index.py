"""Items looked up by heading and box together: the candidates of a cut for one heading.

The inverted walk (:mod:`.follow_inverse`) cuts a swept segment only where the field may change to
or from the heading it tries (:func:`.follow_pieces.crossings` with ``only``): of the vertex lines
and competing pairs whose boxes meet the segment, it keeps the few with that heading. An R-tree
query over the plain boxes returns all of them first (tens per segment near curves and
intersections, a hundred thousand per step). This index files each item once under every heading
bin its headings' neighbourhoods (within twice :data:`WINDOW_RAD`) touch, in one R-tree over a
plane of strips, one per bin: bin b's boxes are shifted along x by b strip widths (a strip is
wider than the items' extent by twice :data:`MARGIN_M`). A query's box, its x range clipped to
the items' extent (widened by half the margin, so it meets the same items) and shifted to its
heading's bin, meets only boxes of that bin. The tree's boxes are grown along x by a slack larger
than the rounding of the shifted coordinates, so the tree returns a superset (along y, unshifted,
its closed-interval test is exact); a query then keeps each item whose box meets its own along x
(closed intervals on the unshifted coordinates, as the R-tree's envelope test) and one of whose
headings lies within the caller's window of it (at most
:data:`WINDOW_RAD`, modulo 2π): exactly what the R-tree query followed by that heading test
finds. Items wanted for every heading (the inverted walk's area boundaries) are filed once in one
more strip, which every query also looks up. One lookup serves any mix of items (the inverted
walk files area boundaries, vertex lines and competing pairs in one index).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

WINDOW_RAD = 1e-5
"""The widest heading window a lookup may ask for (radians, modulo 2π): items are filed under every
bin within twice this of a heading of theirs, so that rounding in the binning cannot lose one
(:data:`.follow_pieces.ONLY_RAD` is narrower)."""

BINS = 2048
"""Heading bins (each 2π / BINS radians wide)."""

MARGIN_M = 1.0
"""Space left between the strips of neighbouring bins, either side of the items' extent (metres)."""

SLACK_M = 1e-6
"""Growth of the tree's boxes beyond the rounding of the shifted coordinates (metres)."""


@dataclass
class HeadingIndex:
    """Items filed in ``tree`` (entry k: item ``item[k]``, its box shifted by its bin's strip, see
    the module docstring; ``everywhere[k]``: filed in the strip after the last bin's, found for
    every heading), with each item's heading columns ``heading`` (radians, NaN: none) and box
    ``bounds`` (rows of x_min, y_min, x_max, y_max; metres). A query's x range is clipped to
    [``low``, ``high``] and shifted by ``shift`` plus its strip's number times ``width`` (metres)."""

    tree: shapely.STRtree
    item: np.ndarray
    everywhere: np.ndarray
    heading: np.ndarray
    bounds: np.ndarray
    low: float
    high: float
    shift: float
    width: float


def heading_index(headings: np.ndarray, bounds: np.ndarray, everywhere: np.ndarray | None = None) -> HeadingIndex:
    """The index of items with headings ``headings[i]`` (a row of columns, 2-D; NaN: none) and
    boxes ``bounds[i]`` (finite); items with ``everywhere[i]`` are found for every heading (their
    headings unused), in one more strip."""
    bounds = np.asarray(bounds, dtype=float).reshape(-1, 4)
    headings = np.asarray(headings, dtype=float)
    everywhere = np.zeros(len(bounds), dtype=bool) if everywhere is None else np.asarray(everywhere, dtype=bool)
    low = float(bounds[:, 0].min(initial=0.0))
    high = float(bounds[:, 2].max(initial=0.0))
    width = high - low + 2 * MARGIN_M
    shift = MARGIN_M - low
    slack = SLACK_M + 64 * float(np.spacing((BINS + 1) * width + abs(shift)))
    item, column = np.nonzero(~np.isnan(headings) & ~everywhere[:, None])
    angle = np.mod(headings[item, column], 2 * np.pi)
    item, first = _expand(item, _bin(angle - 2 * WINDOW_RAD), _bin(angle + 2 * WINDOW_RAD))
    filed = np.unique(item.astype(np.int64) * (BINS + 1) + np.mod(first, BINS))
    filed = np.concatenate([filed, np.flatnonzero(everywhere) * (BINS + 1) + BINS])
    item, strip = (filed // (BINS + 1)).astype(np.intp), filed % (BINS + 1)
    offset, box = strip * width + shift, bounds[item]
    tree = shapely.STRtree(shapely.box(box[:, 0] + offset - slack, box[:, 1], box[:, 2] + offset + slack, box[:, 3]))
    half = MARGIN_M / 2
    return HeadingIndex(tree, item, strip == BINS, headings, bounds, low - half, high + half, shift, width)


def near_heading(
    index: HeadingIndex, heading: np.ndarray, bounds: np.ndarray, window: float = WINDOW_RAD
) -> tuple[np.ndarray, np.ndarray]:
    """(query, item) pairs, each once: item's box meeting ``bounds[query]`` (rows of x_min, y_min,
    x_max, y_max; closed intervals) and the item found for every heading or one of its headings
    within ``window`` (radians, at most :data:`WINDOW_RAD`) of ``heading[query]`` (radians, finite),
    modulo 2π (the turn from one to the other wrapped to [-π, π), as ``(d + π) % 2π - π``)."""
    bounds = np.asarray(bounds, dtype=float).reshape(-1, 4)
    heading = np.asarray(heading, dtype=float)
    n = len(bounds)
    strip = np.mod(_bin(np.mod(heading, 2 * np.pi)), BINS)
    if index.everywhere.any():
        strip = np.append(strip, np.full(n, BINS))
        bounds, heading = np.concatenate([bounds, bounds]), np.concatenate([heading, heading])
    corners = np.empty((len(bounds), 2, 2))
    corners[:, :, 0] = np.clip(bounds[:, 0::2], index.low, index.high) + (strip * index.width + index.shift)[:, None]
    corners[:, :, 1] = bounds[:, 1::2]
    query, entry = index.tree.query(shapely.linestrings(corners))
    item = index.item[entry]
    meet = (bounds[:, 0].take(query) <= index.bounds[:, 2].take(item)) & (
        index.bounds[:, 0].take(item) <= bounds[:, 2].take(query)
    )
    angle, near = heading.take(query), index.everywhere.take(entry)
    for column in index.heading.T:  # a column at a time: numpy reduces slowly along a short axis
        near |= np.abs(_wrapped(column.take(item) - angle + np.pi) - np.pi) <= window
    keep = np.flatnonzero(meet & near)
    return query[keep] % max(n, 1), item[keep]


def _wrapped(angle: np.ndarray) -> np.ndarray:
    """``np.mod(angle, 2 * np.pi)``, bit for bit (in place): the angles already in [0, 2π) are
    their own remainder (0 is not: -0.0 gives 0.0), so only the others (a few) are divided."""
    outside = np.flatnonzero(~((angle > 0) & (angle < 2 * np.pi)))
    angle[outside] = np.mod(angle[outside], 2 * np.pi)
    return angle


def _bin(angle: np.ndarray) -> np.ndarray:
    """The heading bin of each angle (radians), not yet wrapped."""
    return np.floor(angle * (BINS / (2 * np.pi))).astype(np.int64)


def _expand(owner: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner[i], v) for every integer v from low[i] to high[i] (none where high < low)."""
    count = np.maximum(high - low + 1, 0)
    offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    return np.repeat(owner, count), np.repeat(low, count) + offset
