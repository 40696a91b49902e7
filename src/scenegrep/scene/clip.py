"""Lines cut by the regions they must lie in: ``shapely.intersection`` of each line with its domain,
computed part by part where a domain has several parts (the map's intersection areas, its curbs).

An overlay of a line with a multi-part geometry nodes the whole geometry, so it costs as much for a
line that meets one small part as for one that crosses them all; a line whose box meets one part's
box is cut by that part alone, which gives the same geometry (the other parts lie elsewhere: the
overlay finds the same crossings with the same edges), and a line whose box meets several parts'
is cut by the whole domain, as before. A line of some length inside the domain, clear of its
boundary (most of a walk's starts in an intersection area), is its own part inside: the overlay
returns it as it is, so it is not computed (a line of no length, the overlay drops). Each
domain's parts and their R-tree are built once per domain object (kept while it lives).
"""

from __future__ import annotations

import weakref

import numpy as np
import shapely


def clipped(lines: np.ndarray, domains) -> np.ndarray:
    """``shapely.intersection(lines, domains)`` (``domains``: one geometry, or one per line), the
    same geometries (an empty line where a line's box meets no part of a multi-part domain)."""
    lines = np.asarray(lines, dtype=object)
    every = np.empty(len(lines), dtype=object)
    every[:] = [domains] * len(lines) if isinstance(domains, shapely.Geometry) else list(domains)
    found = np.empty(len(lines), dtype=object)
    inside = shapely.contains_properly(every, lines) & (shapely.length(lines) > 0)
    found[inside] = lines[inside]
    whole = ~inside & (shapely.get_num_geometries(every) < 2)
    found[whole] = shapely.intersection(lines[whole], every[whole])
    multi = np.flatnonzero(~inside & ~whole)
    keys = np.array([id(d) for d in every[multi]], dtype=np.int64)
    for key in np.unique(keys).tolist():
        rows = multi[keys == key]
        domain = every[rows[0]]
        parts, tree = _parts(domain)
        line, part = tree.query(lines[rows])
        count = np.bincount(line, minlength=len(rows))
        found[rows] = shapely.LineString()
        one = np.flatnonzero(count[line] == 1)
        found[rows[line[one]]] = shapely.intersection(lines[rows[line[one]]], parts[part[one]])
        many = rows[count > 1]
        found[many] = shapely.intersection(lines[many], domain)
    return found


def _parts(domain: shapely.Geometry) -> tuple[np.ndarray, shapely.STRtree]:
    """A domain's parts and an R-tree of them, built once per domain object (kept by identity: a
    geometry's hash reads all its coordinates)."""
    found = _PARTS.get(id(domain))
    if found is None or found[0]() is not domain:
        parts = shapely.get_parts(domain)
        found = _PARTS[id(domain)] = (weakref.ref(domain, _forget(id(domain))), parts, shapely.STRtree(parts))
    return found[1], found[2]


def _forget(key: int):
    """The callback that drops a domain's parts once the domain is gone (unless the key was
    taken meanwhile by a new domain with the same identity)."""

    def forget(ref: weakref.ref) -> None:
        if _PARTS.get(key, (None,))[0] is ref:
            del _PARTS[key]

    return forget


_PARTS: dict[int, tuple[weakref.ref, np.ndarray, shapely.STRtree]] = {}
