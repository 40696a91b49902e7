"""Items looked up by heading and box together: the candidates of a cut for one heading.

The inverted walk (:mod:`.follow_inverse`) cuts a swept segment only where the field may change to
or from the heading it tries (:func:`.follow_pieces.crossings` with ``only``): of the vertex lines
and competing pairs whose boxes meet the segment, it keeps the few with that heading. An R-tree
query returns all of them first (tens per segment near curves and intersections, a hundred
thousand per step). This index files each item under (heading bin, grid cell) keys, one per bin
its heading's neighbourhood (within twice :data:`WINDOW_RAD`) touches times each cell of
:data:`CELL_M` its box touches, sorted; a query looks up its heading's bin and its box's cells
(one binary search per key) and keeps each item once whose box meets the query's (closed
intervals, as the R-tree's envelope test) and whose heading lies within :data:`WINDOW_RAD`
(modulo 2π). The caller applies its own, narrower heading test to what is returned: together
they find exactly what the R-tree query and that test find.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

WINDOW_RAD = 1e-5
"""Items whose heading differs from the asked one by at most this (radians, modulo 2π) are returned:
wider than :data:`.follow_pieces.ONLY_RAD`, so that rounding cannot lose one."""

BINS = 2048
"""Heading bins (each 2π / BINS radians wide)."""

CELL_M = 8.0
"""Grid cell side (metres)."""


@dataclass
class HeadingIndex:
    """Items filed by key ``(bin * nx + cx) * ny + cy`` (``key`` sorted, ``item`` each key's item;
    cells counted from ``origin``, ``nx`` by ``ny``), with each item's heading columns ``heading``
    (radians, NaN: none) and box ``bounds`` (rows of x_min, y_min, x_max, y_max; metres)."""

    key: np.ndarray
    item: np.ndarray
    heading: np.ndarray
    bounds: np.ndarray
    origin: np.ndarray
    nx: int
    ny: int


def heading_index(headings: np.ndarray, bounds: np.ndarray) -> HeadingIndex:
    """The index of items with headings ``headings[i]`` (a row of columns; NaN: none) and boxes
    ``bounds[i]``."""
    bounds = np.asarray(bounds, dtype=float).reshape(-1, 4)
    headings = np.asarray(headings, dtype=float)
    origin = bounds[:, :2].min(axis=0, initial=0.0) if len(bounds) else np.zeros(2)
    size = np.floor((bounds[:, 2:].max(axis=0, initial=0.0) - origin) / CELL_M).astype(np.int64) + 1
    item, column = np.nonzero(~np.isnan(headings))
    angle = np.mod(headings[item, column], 2 * np.pi)
    low, high = _bin(angle - 2 * WINDOW_RAD), _bin(angle + 2 * WINDOW_RAD)
    item, first = _expand(item, low, high)
    heading_bin = np.mod(first, BINS)
    cells = _cells(bounds[item], origin)
    index = HeadingIndex(np.zeros(0, np.int64), np.zeros(0, np.intp), headings, bounds, origin, *size.tolist())
    owner, key = _keys(index, heading_bin, cells)
    order = np.argsort(key, kind="stable")
    index.key, index.item = key[order], item[owner][order]
    return index


def near_heading(index: HeadingIndex, heading: np.ndarray, bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(query, item) pairs, each once: item's heading within :data:`WINDOW_RAD` of ``heading[query]``
    (radians, modulo 2π) and its box meeting ``bounds[query]`` (rows of x_min, y_min, x_max, y_max)."""
    bounds = np.asarray(bounds, dtype=float)
    heading = np.asarray(heading, dtype=float)
    query, key = _keys(index, np.mod(_bin(np.mod(heading, 2 * np.pi)), BINS), _cells(bounds, index.origin))
    first = np.searchsorted(index.key, key, side="left")
    last = np.searchsorted(index.key, key, side="right")
    query, at = _expand(query, first, last - 1)
    item = index.item[at]
    mine, theirs = bounds[query], index.bounds[item]
    meet = np.all((mine[:, :2] <= theirs[:, 2:]) & (theirs[:, :2] <= mine[:, 2:]), axis=1)
    turn = np.abs(np.mod(index.heading[item] - heading[query][:, None] + np.pi, 2 * np.pi) - np.pi)
    keep = meet & np.any(turn <= WINDOW_RAD, axis=1)
    query, item = query[keep], item[keep]
    size = np.int64(len(index.bounds))
    unique = np.unique(query.astype(np.int64) * size + item)
    return (unique // max(size, 1)).astype(np.intp), (unique % max(size, 1)).astype(np.intp)


def _bin(angle: np.ndarray) -> np.ndarray:
    """The heading bin of each angle (radians), not yet wrapped."""
    return np.floor(angle * (BINS / (2 * np.pi))).astype(np.int64)


def _cells(bounds: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Each box's cell ranges (rows of cx_lo, cy_lo, cx_hi, cy_hi; clipped to the grid by the caller)."""
    low = np.floor((bounds[:, :2] - origin) / CELL_M)
    high = np.floor((bounds[:, 2:] - origin) / CELL_M)
    return np.concatenate([low, high], axis=1)


def _keys(index: HeadingIndex, heading_bin: np.ndarray, cells: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, key) for every grid cell of each row's cell ranges (clipped to the grid) in its bin."""
    top = np.array([index.nx - 1, index.ny - 1], dtype=float)
    low = np.clip(cells[:, :2], 0, top).astype(np.int64)
    high = np.minimum(cells[:, 2:], top).astype(np.int64)
    high = np.where(cells[:, 2:] < 0, -1, high)
    row, cx = _expand(np.arange(len(cells)), low[:, 0], high[:, 0])
    at, cy = _expand(np.arange(len(row)), low[row, 1], high[row, 1])
    row = row[at]
    return row, (heading_bin[row] * index.nx + cx[at]) * index.ny + cy


def _expand(owner: np.ndarray, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(owner[i], v) for every integer v from low[i] to high[i] (none where high < low)."""
    count = np.maximum(high - low + 1, 0)
    offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    return np.repeat(owner, count), np.repeat(low, count) + offset
