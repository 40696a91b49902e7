"""Regions over unknown map layers (see :mod:`scenegrep.model.layers`): which unknown layers a
region needs on a map, and the region with those layers replaced by an assumption.

A region needs an unknown layer unless the rest of the region decides without it: on a map that
gives its drivable area explicitly (AV2), the shoulders lie inside it, so Scenic's
``roadOrShoulder`` (drivable area or shoulder) is the drivable area and needs no shoulder layer.
"""

from __future__ import annotations

from .regions import Combination, Difference, Everywhere, Intersection, MapRegion, Nowhere, Region, Union


def reduced(region: Region, shoulders_in_drivable: bool) -> Region:
    """``region`` without shoulder parts of unions that hold the drivable area, when the map's
    drivable area holds its shoulders (``shoulders_in_drivable``); else ``region`` itself."""
    if not shoulders_in_drivable:
        return region
    if isinstance(region, Union) and MapRegion("drivable") in region.parts:
        return _union(tuple(reduced(p, True) for p in region.parts if p != MapRegion("shoulder")))
    if isinstance(region, Combination):
        return type(region)(tuple(reduced(p, True) for p in region.parts))
    if isinstance(region, Difference):
        return Difference(reduced(region.base, True), reduced(region.removed, True))
    return region


def needed(region: Region, unknown: set[str]) -> set[str]:
    """The unknown layers ``region`` reads."""
    return unknown.intersection(region.layers())


def assumed(region: Region, unknown: set[str], everywhere: bool) -> Region:
    """``region`` with every layer in ``unknown`` replaced by :class:`Everywhere` (``everywhere``)
    or :class:`Nowhere`, and the result simplified so that the other layers keep their own shape."""
    if isinstance(region, MapRegion) and region.layer in unknown:
        return Everywhere() if everywhere else Nowhere()
    if isinstance(region, Union):
        return _union(tuple(assumed(p, unknown, everywhere) for p in region.parts))
    if isinstance(region, Intersection):
        return _intersection(tuple(assumed(p, unknown, everywhere) for p in region.parts))
    if isinstance(region, Difference):
        return _difference(assumed(region.base, unknown, everywhere), assumed(region.removed, unknown, everywhere))
    return region


def _union(parts: tuple[Region, ...]) -> Region:
    if any(isinstance(p, Everywhere) for p in parts):
        return Everywhere()
    kept = tuple(p for p in parts if not isinstance(p, Nowhere))
    return kept[0] if len(kept) == 1 else Union(kept) if kept else Nowhere()


def _intersection(parts: tuple[Region, ...]) -> Region:
    if any(isinstance(p, Nowhere) for p in parts):
        return Nowhere()
    kept = tuple(p for p in parts if not isinstance(p, Everywhere))
    return kept[0] if len(kept) == 1 else Intersection(kept) if kept else Everywhere()


def _difference(base: Region, removed: Region) -> Region:
    if isinstance(base, Nowhere) or isinstance(removed, Everywhere):
        return Nowhere()
    return base if isinstance(removed, Nowhere) else Difference(base, removed)
