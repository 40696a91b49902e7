"""The meaning of regions and fields over a concrete road map, for arrays of known points.

:class:`MapGeometry` answers the geometric terms of :mod:`.terms` for arrays of
rows, given a function ``value(term)`` that evaluates a region's term
parameters for the same rows:

* points in a region (map layers by R-tree point-in-polygon, exact; sectors
  analytically; a curb point lies within 1 µm of a curb polyline);
* whether a small axis-aligned box (a point known up to the position
  tolerance) meets a region — sound: never False when the box meets it;
* oriented boxes inside a region (Scenic's ``containsObject``);
* distances to regions; the headings of a field at points — several where
  lanes overlap (intersections), each a possible value of Scenic's
  ``roadDirection`` there (Scenic picks one arbitrarily); off every lane both
  Scenic's default 0 (right outside the road network) and the nearest lane's
  direction (on road or shoulder areas outside lanes, where Scenic uses that
  element's own orientation).

Layers the map's format does not publish (:attr:`~scenegrep.model.RoadMap.unknown_layers`)
are *unknown*; a layer it publishes with no elements is empty. Every public query first reduces
the region (:func:`.unknown.reduced`: on a map that gives its drivable area but no shoulders, the
shoulders lie in the drivable area), then, when the region still reads an unknown layer, applies
the user's choice (:class:`~scenegrep.model.layers.UnknownLayers`): without one it is an error
naming the layer; with one the layer is everywhere (permissive) or empty (strict), and the rows
whose answer differs under the other assumption are counted as decisions the assumption affected.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable
from functools import cached_property

import numpy as np
import shapely
from shapely import STRtree

from ..errors import UserError
from ..model import RoadMap
from ..model.geometry import box_corners
from ..model.layers import UnknownLayers
from ..model.polylines import Polylines
from ..model.roadmap import tree_containing
from . import shapes
from .regions import (
    ELEMENT_FIELDS,
    Difference,
    Everywhere,
    Field,
    Intersection,
    LaneAt,
    LaneDirection,
    MapField,
    MapRegion,
    Nowhere,
    Region,
    Sector,
    Union,
)
from .terms import Term
from .unknown import assumed, needed, reduced

Values = Callable[[Term], np.ndarray]

CURB_REACH_M = 1e-6
"""A point is on a curb when it lies within this distance of a curb polyline."""

ELEMENT_REACH_M = 0.05
"""Scenic's road-network tolerance (``Network.fromOpenDrive``'s default): a point in no sidewalk
or crossing takes the direction of the first within this distance (Scenic's union of them is
built with this buffer, and its orientation tries that tolerance next)."""

NEAR_M = ELEMENT_REACH_M + 1e-6
"""Points with no lane within this (metres; Scenic's tolerance, and slack for rounding) have no
lane within the tolerance: the nearest lane is not looked up for them."""

GEOMETRY_CACHE_SIZE = 8
"""How many road maps' geometries :func:`geometry_of` keeps (least recently used dropped)."""


def geometry_of(road_map: RoadMap | None, unknown_layers: UnknownLayers | None = None) -> MapGeometry:
    """The :class:`MapGeometry` of ``road_map`` under the choice ``unknown_layers`` (None: no
    choice), shared by every query over the same map object and choice (its layer unions and
    region geometries are built once, on first use); the last :data:`GEOMETRY_CACHE_SIZE` are kept."""
    if road_map is None:
        return MapGeometry(None, unknown_layers)
    key = (id(road_map), id(unknown_layers))
    geometry = _GEOMETRIES.pop(key, None)
    if geometry is None:
        geometry = MapGeometry(road_map, unknown_layers)
    _GEOMETRIES[key] = geometry
    while len(_GEOMETRIES) > GEOMETRY_CACHE_SIZE:
        _GEOMETRIES.popitem(last=False)
    return geometry


class MapGeometry:
    """Geometric queries over one road map (or none: only map-free regions then), under a choice
    for its unknown layers (see the module docstring)."""

    def __init__(self, road_map: RoadMap | None, unknown_layers: UnknownLayers | None = None):
        self.map = road_map
        self.choice = unknown_layers or UnknownLayers()
        self.unknown = set(road_map.unknown_layers) if road_map is not None else set()
        self._shoulders_in_drivable = (
            road_map is not None and road_map.drivable_area is not None and not road_map.publishes("shoulder")
        )
        self._static: dict[Region, shapely.Geometry | None] = {}
        self._element_cache: dict[str, tuple[STRtree, Polylines]] = {}

    # ---------------------------------------------------------------- layers
    def unknown_needed(self, region: Region) -> set[str]:
        """The unknown layers a decision about ``region`` needs on this map."""
        return needed(reduced(region, self._shoulders_in_drivable), self.unknown)

    def _decided(self, region: Region, decide: Callable[[Region], np.ndarray]) -> np.ndarray:
        """``decide(region)`` with the unknown layers it needs replaced as the user chose; counts
        the rows whose answer the choice decided; an error naming the layer without a choice."""
        region = reduced(region, self._shoulders_in_drivable)
        layers = needed(region, self.unknown)
        if not layers:
            return decide(region)
        chosen = decide(self._assumed(region, layers))
        other = decide(assumed(region, layers, not self.choice.everywhere))
        self.choice.count("+".join(sorted(layers)), np.count_nonzero(chosen != other))
        return chosen

    def _assumed(self, region: Region, layers: set[str]) -> Region:
        if self.choice.mode is None:
            name = self.map.name if self.map is not None else "?"
            raise self.choice.refuse(layers, "a region of the query", name)
        return assumed(region, layers, self.choice.everywhere)

    def _known(self, region: Region) -> Region:
        """``region`` reduced, with its unknown layers replaced as the user chose (not counted)."""
        region = reduced(region, self._shoulders_in_drivable)
        layers = needed(region, self.unknown)
        return self._assumed(region, layers) if layers else region

    def _require_map(self) -> RoadMap:
        if self.map is None:
            raise UserError("the query uses map regions, but the data has no road map (give one with --map)")
        return self.map

    @cached_property
    def _layer_parts(self) -> dict[str, np.ndarray]:
        road_map = self._require_map()
        parts = {
            "drivable": [road_map.drivable],
            "road": [a.polygon for a in road_map.roads] or list(road_map.lane_polygons),
            "lane": list(road_map.lane_polygons),
            "intersection": [a.polygon for a in road_map.intersections]
            + list(road_map.lane_polygons[road_map.lane_is_intersection]),
            "crossing": [a.polygon for a in road_map.crosswalks],
            "sidewalk": [a.polygon for a in road_map.sidewalks],
            "curb": list(road_map.curb_polylines.geometries),
            "shoulder": [a.polygon for a in road_map.shoulders],
        }
        return {name: np.array([g for g in geoms if not g.is_empty], dtype=object) for name, geoms in parts.items()}

    @cached_property
    def _trees(self) -> dict[str, STRtree]:
        return {name: STRtree(parts) for name, parts in self._layer_parts.items()}

    @cached_property
    def _unions(self) -> dict[str, shapely.Geometry]:
        unions = {}
        for name, parts in self._layer_parts.items():
            union = shapely.union_all(parts) if len(parts) else shapely.GeometryCollection()
            shapely.prepare(union)
            unions[name] = union
        return unions

    def _layer_hits(self, layer: str, geometries: np.ndarray, predicate: str) -> np.ndarray:
        hit = np.zeros(len(geometries), dtype=bool)
        if len(self._layer_parts[layer]):
            hit[self._trees[layer].query(geometries, predicate=predicate)[0]] = True
        return hit

    # ---------------------------------------------------------------- points
    def contains_points(self, region: Region, x: np.ndarray, y: np.ndarray, value: Values) -> np.ndarray:
        """Whether each point (x[i], y[i]) lies in the region (boundary included)."""
        return self.boxes_meet(region, x, x, y, y, value)

    def boxes_meet(
        self, region: Region, x_lo: np.ndarray, x_hi: np.ndarray, y_lo: np.ndarray, y_hi: np.ndarray, value: Values
    ) -> np.ndarray:
        """Whether the axis-aligned box [x_lo, x_hi] x [y_lo, y_hi] of each row may meet the region.

        Exact for map layers and degenerate boxes (points); for sectors and combinations of
        regions it may say True for a box that misses the region by at most its diagonal.
        """
        return self._decided(region, lambda r: self._boxes_meet(r, x_lo, x_hi, y_lo, y_hi, value))

    def _boxes_meet(self, region: Region, x_lo, x_hi, y_lo, y_hi, value: Values) -> np.ndarray:
        n = len(x_lo)
        if (constant := _constant(region, n)) is not None:
            return constant
        if isinstance(region, MapRegion):
            boxes = shapely.box(x_lo, y_lo, x_hi, y_hi)
            if region.layer == "curb":
                boxes = shapely.buffer(boxes, CURB_REACH_M, cap_style="square", join_style="mitre")
            return self._layer_hits(region.layer, boxes, "intersects")
        if isinstance(region, Sector):
            cx, cy = (x_lo + x_hi) / 2, (y_lo + y_hi) / 2
            reach = np.hypot(x_hi - x_lo, y_hi - y_lo) / 2
            return shapes.points_near_sector(cx, cy, *(value(t) for t in region.terms()), reach)
        if isinstance(region, LaneAt):
            return self._boxes_meet_lane_of(x_lo, x_hi, y_lo, y_hi, value(region.x), value(region.y))
        if isinstance(region, Intersection):
            hit = np.ones(n, dtype=bool)
            for part in region.parts:
                hit &= self._boxes_meet(part, x_lo, x_hi, y_lo, y_hi, value)
            return hit
        if isinstance(region, Union):
            hit = np.zeros(n, dtype=bool)
            for part in region.parts:
                hit |= self._boxes_meet(part, x_lo, x_hi, y_lo, y_hi, value)
            return hit
        if isinstance(region, Difference):
            inside_removed = self._aligned_boxes_inside(region.removed, x_lo, x_hi, y_lo, y_hi, value)
            return self._boxes_meet(region.base, x_lo, x_hi, y_lo, y_hi, value) & ~inside_removed
        raise TypeError(f"unknown region {region!r}")

    def _aligned_boxes_inside(self, region: Region, x_lo, x_hi, y_lo, y_hi, value: Values) -> np.ndarray:
        """Whether each axis-aligned box lies wholly inside the region (used to exclude boxes)."""
        x, y = (x_lo + x_hi) / 2, (y_lo + y_hi) / 2
        return self._contains_boxes(region, x, y, np.zeros_like(x), y_hi - y_lo, x_hi - x_lo, value)

    def _boxes_meet_lane_of(self, x_lo, x_hi, y_lo, y_hi, ax, ay) -> np.ndarray:
        road_map = self._require_map()
        rows, lanes = road_map.lanes_containing(ax, ay)
        boxes = shapely.box(x_lo[rows], y_lo[rows], x_hi[rows], y_hi[rows])
        hit = np.zeros(len(x_lo), dtype=bool)
        hit[rows[shapely.intersects(road_map.lane_polygons[lanes], boxes)]] = True
        return hit

    def region_bounds(self, region: Region, value: Values) -> tuple[float, float, float, float] | None:
        """(min x, min y, max x, max y) enclosing the region (one row of its parameters), None if empty."""
        region = self._known(region)
        if isinstance(region, Nowhere):
            return None
        if isinstance(region, Everywhere):
            return (-1e7, -1e7, 1e7, 1e7)
        if isinstance(region, MapRegion):
            union = self._unions[region.layer]
            return None if union.is_empty else tuple(union.bounds)
        if isinstance(region, Sector):
            cx, cy, radius = (float(value(t)[0]) for t in (region.cx, region.cy, region.radius))
            return (cx - radius, cy - radius, cx + radius, cy + radius)
        if isinstance(region, LaneAt):
            road_map = self._require_map()
            lanes = road_map.lanes_containing(value(region.x)[:1], value(region.y)[:1])[1]
            return tuple(shapely.total_bounds(road_map.lane_polygons[lanes])) if len(lanes) else None
        if isinstance(region, Difference):
            return self.region_bounds(region.base, value)
        parts = [self.region_bounds(p, value) for p in region.parts]  # type: ignore[attr-defined]
        if isinstance(region, Union):
            present = [b for b in parts if b is not None]
            if not present:
                return None
            return (
                min(b[0] for b in present),
                min(b[1] for b in present),
                max(b[2] for b in present),
                max(b[3] for b in present),
            )
        if any(b is None for b in parts):
            return None
        box = (max(b[0] for b in parts), max(b[1] for b in parts), min(b[2] for b in parts), min(b[3] for b in parts))
        return box if box[0] <= box[2] and box[1] <= box[3] else None

    def static_geometry(self, region: Region) -> shapely.Geometry | None:
        """The region as one (prepared) shapely geometry when it is made of known map layers only,
        else None; computed once per region."""
        if region not in self._static:
            geometry = self._static_geometry(self._known(region))
            if geometry is not None:
                shapely.prepare(geometry)
            self._static[region] = geometry
        return self._static[region]

    def _static_geometry(self, region: Region) -> shapely.Geometry | None:
        if isinstance(region, Nowhere):
            return shapely.GeometryCollection()
        if isinstance(region, MapRegion):
            self._require_map()
            return self._unions[region.layer]
        if isinstance(region, (Union, Intersection)):
            parts = [self.static_geometry(p) for p in region.parts]
            if any(p is None for p in parts):
                return None
            return shapely.union_all(parts) if isinstance(region, Union) else shapely.intersection_all(parts)
        if isinstance(region, Difference):
            base, removed = self.static_geometry(region.base), self.static_geometry(region.removed)
            return None if base is None or removed is None else shapely.difference(base, removed)
        return None

    # ---------------------------------------------------------------- oriented boxes
    def contains_boxes(self, region: Region, x, y, heading, length, width, value: Values) -> np.ndarray:
        """Whether each oriented box lies inside the region (Scenic's ``containsObject``)."""
        return self._decided(region, lambda r: self._contains_boxes(r, x, y, heading, length, width, value))

    def _contains_boxes(self, region: Region, x, y, heading, length, width, value: Values) -> np.ndarray:
        n = len(np.atleast_1d(x))
        if (constant := _constant(region, n)) is not None:
            return constant
        if isinstance(region, Sector):
            return shapes.boxes_in_sectors(x, y, heading, length, width, *(value(t) for t in region.terms()))
        if isinstance(region, Intersection):
            inside = np.ones(n, dtype=bool)
            for part in region.parts:
                inside &= self._contains_boxes(part, x, y, heading, length, width, value)
            return inside
        if isinstance(region, Difference):
            base = self._contains_boxes(region.base, x, y, heading, length, width, value)
            return base & ~self._boxes_meet_oriented(region.removed, x, y, heading, length, width, value)
        polygons = _box_polygons(x, y, heading, length, width)
        if isinstance(region, LaneAt):
            road_map = self._require_map()
            rows, lanes = road_map.lanes_containing(value(region.x), value(region.y))
            inside = np.zeros(n, dtype=bool)
            inside[rows[shapely.contains(road_map.lane_polygons[lanes], polygons[rows])]] = True
            return inside
        return shapely.contains(self._static_union(region), polygons)

    def boxes_meet_oriented(self, region: Region, x, y, heading, length, width, value: Values) -> np.ndarray:
        """Whether each oriented box intersects the region (touching counts)."""
        return self._decided(region, lambda r: self._boxes_meet_oriented(r, x, y, heading, length, width, value))

    def _boxes_meet_oriented(self, region: Region, x, y, heading, length, width, value: Values) -> np.ndarray:
        n = len(np.atleast_1d(x))
        if (constant := _constant(region, n)) is not None:
            return constant
        if isinstance(region, Sector):
            return shapes.boxes_meet_sectors(x, y, heading, length, width, *(value(t) for t in region.terms()))
        if isinstance(region, Union):
            hit = np.zeros(n, dtype=bool)
            for part in region.parts:
                hit |= self._boxes_meet_oriented(part, x, y, heading, length, width, value)
            return hit
        if isinstance(region, MapRegion):
            return self._layer_hits(region.layer, _box_polygons(x, y, heading, length, width), "intersects")
        raise UserError(f"testing whether an object meets {_describe(region)} is not supported")

    def _static_union(self, region: Region) -> shapely.Geometry:
        """The shapely geometry of a region built only from known map layers."""
        geometry = self.static_geometry(region)
        if geometry is None:
            raise UserError(f"containment in {_describe(region)} is not supported")
        return geometry

    # ---------------------------------------------------------------- distances and fields
    def distances(self, region: Region, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Distance (m) from each point to the region (0 inside; infinite to an empty region)."""
        return self._decided(region, lambda r: self._distances(r, x, y))

    def _distances(self, region: Region, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        if isinstance(region, (Everywhere, Nowhere)):
            return np.full(len(np.atleast_1d(x)), 0.0 if isinstance(region, Everywhere) else np.inf)
        if isinstance(region, MapRegion):
            return self._layer_distances(region.layer, x, y)
        if isinstance(region, Union) and all(isinstance(p, MapRegion) for p in region.parts):
            return np.min([self._distances(p, x, y) for p in region.parts], axis=0)
        raise UserError(f"the distance to {_describe(region)} is not supported")

    def _layer_distances(self, layer: str, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Distance (m) from each point to a map layer: to its nearest element, found in the layer's
        R-tree (the distance to the layer's union, without measuring against the whole union)."""
        distances = np.full(len(np.atleast_1d(x)), np.inf)
        if len(self._layer_parts[layer]):
            points = shapely.points(np.atleast_1d(x), np.atleast_1d(y))
            (rows, _), nearest = self._trees[layer].query_nearest(points, return_distance=True, all_matches=False)
            distances[rows] = nearest
        return distances

    def unoriented(self, field: Field) -> set[str]:
        """The layers (``sidewalk``, ``crossing``) whose elements' directions ``field`` reads and
        the map does not give (an unknown layer, or elements without centrelines)."""
        if self.map is None or not (isinstance(field, MapField) and field.name in ELEMENT_FIELDS):
            return set()
        return {layer for layer in ELEMENT_FIELDS[field.name] if not self.map.orients(layer)}

    def field_values(self, field: Field, x: np.ndarray, y: np.ndarray, value: Values) -> tuple[np.ndarray, np.ndarray]:
        """The possible headings of a field at each point, as (row index, heading) pairs sorted by row.

        Every row has at least one value when the map has lanes (or curbs, for the curb field; or
        elements, for the sidewalk and crossing fields: under ``--unknown-layers strict`` a field the
        map does not give has none).
        """
        road_map = self._require_map()
        if isinstance(field, MapField) and field.name in ELEMENT_FIELDS:
            return self._element_directions(field, x, y)
        if isinstance(field, MapField) and field.name == "curb":
            if not len(road_map.curb_polylines):
                raise UserError("the query uses the curb, but the road map has no curbs")
            line = self._trees["curb"].nearest(shapely.points(x, y))
            return np.arange(len(x)), road_map.curb_polylines.direction_at(line, x, y)
        if isinstance(field, LaneDirection):
            rows, lanes = road_map.lanes_containing(value(field.x), value(field.y))
            return rows, road_map.centreline_polylines.direction_at(lanes, x[rows], y[rows])
        rows, lanes = road_map.lanes_containing(x, y)
        headings = road_map.centreline_polylines.direction_at(lanes, x[rows], y[rows])
        missing = np.setdiff1d(np.arange(len(x)), rows)
        if len(missing):
            rows, headings = _off_lane(road_map, x, y, missing, rows, headings)
            scenic = self._off_lanes(x[missing], y[missing])
            rows, headings = np.concatenate([rows, missing]), np.concatenate([headings, scenic])
            order = np.argsort(rows, kind="stable")
            rows, headings = rows[order], headings[order]
        return rows, headings

    def _elements(self, name: str) -> tuple[STRtree, Polylines]:
        """An R-tree of the polygons of the elements giving the field ``name`` (one of
        :data:`.regions.ELEMENT_FIELDS`, which the map gives) and their centrelines, in Scenic's
        order (sidewalks, then crossings); built once."""
        if name not in self._element_cache:
            road_map = self._require_map()
            held = {"sidewalk": road_map.sidewalks, "crossing": road_map.crosswalks}
            areas = [a for layer in ELEMENT_FIELDS[name] for a in held[layer]]
            polygons = np.array([a.polygon for a in areas], dtype=object)
            lines = Polylines([a.centreline for a in areas if a.centreline is not None])
            self._element_cache[name] = (STRtree(polygons), lines)
        return self._element_cache[name]

    def _element_directions(self, field: MapField, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Scenic's orientation of sidewalks, crossings or both at each point: the direction of the
        first element containing it, else of the first within :data:`ELEMENT_REACH_M`, else of the
        nearest (a labeled point off every element, where Scenic rejects: the nearest stands for
        the element Scenic's point was in), each the heading of its centreline's segment nearest
        by projection. No value on a map without elements, or (strict) without their directions:
        then the rows are counted as decisions of the choice (each refused by it)."""
        missing = self.unoriented(field)
        if missing:
            if self.choice.mode != "strict":
                map_name = self.map.name if self.map is not None else "?"
                raise self.choice.refuse_direction(missing, "a region's orientation in the query", map_name)
            self.choice.count(f"{'+'.join(sorted(missing))} direction", len(x))
            return np.zeros(0, np.intp), np.zeros(0)
        tree, lines = self._elements(field.name)
        if not len(lines):
            return np.zeros(0, np.intp), np.zeros(0)
        points = shapely.points(x, y)
        element = np.full(len(x), len(lines), dtype=np.intp)
        for predicate, reach in (("intersects", 0.0), ("dwithin", ELEMENT_REACH_M)):
            open_rows = np.flatnonzero(element == len(lines))
            point, found = tree.query(points[open_rows], predicate=predicate, distance=reach or None)
            np.minimum.at(element, open_rows[point], found)
        open_rows = np.flatnonzero(element == len(lines))
        if len(open_rows):
            element[open_rows] = tree.nearest(points[open_rows])
        return np.arange(len(x)), lines.direction_at(element, x, y)

    def _uniform_headings(
        self, field: Field, x0: float, x1: float, y0: float, y1: float, value: Values
    ) -> np.ndarray | None:
        """The headings shared by a small box's corners and centre, or None when they differ."""
        xs = np.array([x0, x1, x0, x1, (x0 + x1) / 2])
        ys = np.array([y0, y0, y1, y1, (y0 + y1) / 2])
        rows, headings = self.field_values(field, xs, ys, lambda t: np.repeat(value(t)[:1], 5))
        sets = [np.unique(headings[rows == k]) for k in range(5)]
        if all(len(s) == len(sets[0]) and np.array_equal(s, sets[0]) for s in sets[1:]):
            return sets[0]
        return None

    @cached_property
    def _intersection_areas(self) -> tuple[STRtree, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """An R-tree of the intersection areas, their lanes' indices (in the map's order) one area
        after another, where each area's lanes start in that array (one past the last at the end),
        and each (area, lane) membership as ``area * lanes + lane``, sorted, with the lane's first
        position in the area's list."""
        road_map = self._require_map()
        index = road_map.lane_index
        areas = list(road_map.intersections)
        lanes = [[index[lane] for lane in a.lanes if lane in index] for a in areas]
        starts = np.concatenate([[0], np.cumsum([len(group) for group in lanes])]).astype(np.intp)
        flat = np.array([lane for group in lanes for lane in group], dtype=np.intp)
        polygons = np.array([a.polygon for a in areas], dtype=object)
        shapely.prepare(polygons)
        owner = np.repeat(np.arange(len(areas)), np.diff(starts))
        position = np.arange(len(flat)) - starts[owner]
        member = owner * np.int64(len(road_map.lanes)) + flat
        order = np.lexsort((position, member))
        first = _firsts(member[order])
        return STRtree(polygons), flat, starts, member[order][first], position[order][first]

    def scenic_headings(self, field: Field, x: np.ndarray, y: np.ndarray, value: Values) -> np.ndarray:
        """The one heading Scenic itself computes for the field at each point (used to walk along it).

        Scenic's ``roadDirection`` takes the first intersection containing the point and, there, the
        first of its connecting lanes (in maneuver order) containing it, else the nearest; elsewhere
        the first lane containing the point; outside every lane the first shoulder holding it (along
        its centreline), else the first element within Scenic's tolerance (:meth:`_off_lanes`), else
        0. Exact on OpenDRIVE maps, whose intersections keep Scenic's maneuver order, except on road
        area outside every lane (0.3 m² on Town01), where Scenic takes the road's own centreline
        direction (the map model holds no road centrelines) and this gives 0, and within the
        tolerance of a road, where it takes the nearest lane for the first of Scenic's lanes there.
        """
        if not (isinstance(field, MapField) and field.name == "lanes"):
            rows, headings = self.field_values(field, x, y, value)
            chosen = np.zeros(len(x))
            chosen[rows[_firsts(rows)]] = headings[_firsts(rows)]
            return chosen
        road_map = self._require_map()
        points = shapely.points(x, y)
        lane = np.full(len(x), -1, dtype=np.intp)
        if len(x):
            inside = np.zeros(0, np.int64)
            if len(road_map.lanes):
                rows, lanes = tree_containing(road_map._lane_tree, points)
                inside = np.sort(rows * np.int64(len(road_map.lanes)) + lanes)
                rows, lanes = _first_per_point(rows, lanes)
                lane[rows] = lanes
            self._intersection_choice(points, lane, 0.0, inside)
        chosen = np.zeros(len(x))
        off = np.flatnonzero(lane < 0)
        if len(off):
            chosen[off] = self._off_lanes(x[off], y[off], points[off])
        on = np.flatnonzero(lane >= 0)
        chosen[on] = road_map.centreline_polylines.direction_at(lane[on], x[on], y[on])
        return chosen

    @cached_property
    def _shoulders(self) -> tuple[STRtree, Polylines] | None:
        """An R-tree of the shoulders and their centrelines, when every shoulder has one (OpenDRIVE
        maps): Scenic orients a shoulder along the nearest segment of its centreline."""
        areas = self._require_map().shoulders
        if not areas or any(a.centreline is None for a in areas):
            return None
        polygons = np.array([a.polygon for a in areas], dtype=object)
        shapely.prepare(polygons)
        return STRtree(polygons), Polylines([a.centreline for a in areas])

    def _off_lanes(self, x: np.ndarray, y: np.ndarray, points: np.ndarray | None = None) -> np.ndarray:
        """Scenic's road direction at points in no lane and no intersection area: the first shoulder
        holding the point; else, within :data:`ELEMENT_REACH_M` (Scenic's second pass over its
        elements, in its order), an intersection (its lane as inside one), the nearest lane
        (standing for the lane of its road), the first shoulder; else 0 (radians). ``points``: the
        points as shapely points when the caller has them."""
        road_map = self._require_map()
        chosen = np.zeros(len(x))
        points = shapely.points(x, y) if points is None else points
        shoulders = self._shoulders
        if shoulders is not None:
            point, shoulder = _first_per_point(*tree_containing(shoulders[0], points))
            chosen[point] = shoulders[1].direction_at(shoulder, x[point], y[point])
            elsewhere = np.ones(len(x), dtype=bool)
            elsewhere[point] = False
            rest = np.flatnonzero(elsewhere)
        else:
            rest = np.arange(len(x))
        lane = np.full(len(rest), -1, dtype=np.intp)
        if len(rest):
            self._intersection_choice(points[rest], lane, ELEMENT_REACH_M, np.zeros(0, np.int64))
        free = np.flatnonzero(lane < 0) if len(road_map.lanes) else np.zeros(0, np.intp)
        if len(free):
            close = road_map._lane_tree.query(points[rest[free]], predicate="dwithin", distance=NEAR_M)[0]
            free = free[np.unique(close)]
        if len(free):
            nearest = road_map._lane_tree.nearest(points[rest[free]])
            near = shapely.distance(road_map.lane_polygons[nearest], points[rest[free]]) <= ELEMENT_REACH_M
            lane[free[near]] = nearest[near]
        on = np.flatnonzero(lane >= 0)
        chosen[rest[on]] = road_map.centreline_polylines.direction_at(lane[on], x[rest[on]], y[rest[on]])
        free = rest[lane < 0]
        if len(free) and shoulders is not None:
            tree, lines = shoulders
            point, shoulder = _first_per_point(*tree.query(points[free], predicate="dwithin", distance=ELEMENT_REACH_M))
            chosen[free[point]] = lines.direction_at(shoulder, x[free[point]], y[free[point]])
        return chosen

    def _intersection_choice(self, points: np.ndarray, lane: np.ndarray, reach: float, inside: np.ndarray) -> None:
        """Points (shapely) in an intersection area (or within ``reach`` metres of one) take the first
        of its lanes containing them, else the nearest (the first such intersection area counts; of
        equally near lanes the first): set in ``lane``. ``inside``: every lane containing each
        point, as ``point * lanes + lane`` sorted (the caller has found them; none for points in no
        lane), so only points in none of their area's lanes are measured against them."""
        road_map = self._require_map()
        tree, flat, starts, member, rank = self._intersection_areas
        if not len(flat):
            return
        if reach > 0:
            point, area = tree.query(points, predicate="dwithin", distance=reach)
        else:
            point, area = tree_containing(tree, points)
        if not len(point):
            return
        point, area = _first_per_point(point, area)
        lanes = np.int64(len(road_map.lanes))
        first = np.full(len(point), len(flat))
        if len(inside):
            held = inside // lanes
            k = np.minimum(np.searchsorted(point, held), len(point) - 1)
            code = area[k] * lanes + inside % lanes
            at = np.minimum(np.searchsorted(member, code), len(member) - 1)
            hit = (point[k] == held) & (member[at] == code)
            np.minimum.at(first, k[hit], rank[at[hit]])
        held = first < len(flat)
        lane[point[held]] = flat[starts[area[held]] + first[held]]
        point, area = point[~held], area[~held]
        if not len(point):
            return
        counts = starts[area + 1] - starts[area]
        group = np.repeat(np.arange(len(point)), counts)
        position = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        candidates = flat[starts[area][group] + position]
        score = shapely.distance(road_map.lane_polygons[candidates], points[point[group]])
        order = np.lexsort((position, score, group))
        best = order[_firsts(group[order])]
        lane[point[group[best]]] = candidates[best]

    def field_headings_in_box(
        self, field: Field, x0: float, x1: float, y0: float, y1: float, value: Values
    ) -> np.ndarray | None:
        """Every heading the field may take at a point of the box [x0, x1] x [y0, y1] (a superset),
        or None — any heading — for a box wider than :data:`WIDE_BOX_M` (not worth the lookup).

        A point's heading is that of the segment of a polyline (lane centreline or curb) nearest to
        it; for any point of the box that segment lies within d + 2h of the box centre, where d is
        the centre's distance to the polyline and h the half-diagonal, so those segments' headings
        cover every point of the box. A sidewalk or crossing field takes the centreline of an
        element meeting the box, within :data:`ELEMENT_REACH_M` of one of its points, or nearest to
        one: every such element lies within max(d + 2h, reach + h) of the centre, d the distance
        to the nearest element.
        """
        road_map = self._require_map()
        cx, cy, h = (x0 + x1) / 2, (y0 + y1) / 2, math.hypot(x1 - x0, y1 - y0) / 2
        if h > WIDE_BOX_M:
            return None
        if h <= SMALL_BOX_M:
            uniform = self._uniform_headings(field, x0, x1, y0, y1, value)
            if uniform is not None:
                return uniform
        centre = shapely.Point(cx, cy)
        if isinstance(field, MapField) and field.name in ELEMENT_FIELDS:
            if self.unoriented(field) or not len(self._elements(field.name)[1]):
                return self._element_directions(field, np.zeros(0), np.zeros(0))[1]  # none (or the error)
            tree, polylines = self._elements(field.name)
            nearest = shapely.distance(tree.geometries[tree.nearest(centre)], centre)
            reach = max(nearest + 2 * h, ELEMENT_REACH_M + h)
            lines = tree.query(centre, predicate="dwithin", distance=reach)
        elif isinstance(field, MapField) and field.name == "curb":
            polylines, tree = road_map.curb_polylines, self._trees["curb"]
            nearest = shapely.distance(tree.geometries[tree.nearest(centre)], centre)
            lines = tree.query(centre, predicate="dwithin", distance=nearest + 2 * h)
            headings = []
        elif isinstance(field, LaneDirection):
            polylines = road_map.centreline_polylines
            lines = road_map.lanes_containing(value(field.x)[:1], value(field.y)[:1])[1]
            headings = []
        else:
            polylines = road_map.centreline_polylines
            box = shapely.box(x0, y0, x1, y1)
            lines = road_map._lane_tree.query(box, predicate="intersects")
            if not self._unions["lane"].contains(box) and len(road_map.lanes):
                nearest = shapely.distance(road_map.lane_polygons[road_map._lane_tree.nearest(centre)], centre)
                lines = np.union1d(
                    lines, road_map._lane_tree.query(centre, predicate="dwithin", distance=nearest + 2 * h)
                )
        headings = []
        for line in np.asarray(lines, dtype=np.intp).tolist():
            first, count = polylines.first[line], polylines.count[line]
            segments = slice(first, first + count)
            distance = _segment_distances(polylines.start[segments], polylines.end[segments], cx, cy)
            if len(distance):
                headings.append(polylines.heading[segments][distance <= distance.min() + 2 * h + 1e-9])
        return np.concatenate(headings) if headings else np.zeros(0)


WIDE_BOX_M = 10.0
"""Half-diagonal (m) beyond which a box's field headings are not looked up (any heading)."""

SMALL_BOX_M = 0.01
"""Boxes with a half-diagonal up to this (m) whose corners and centre all take the same headings
are taken to lie in one cell of the field (cells are convex at that scale)."""


def _firsts(rows: np.ndarray) -> np.ndarray:
    """Whether each entry of a sorted array is the first of its value."""
    first = np.ones(len(rows), dtype=bool)
    first[1:] = rows[1:] != rows[:-1]
    return first


def _first_per_point(point: np.ndarray, area: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For (point, area) pairs, each point's lowest area, points ascending."""
    order = np.lexsort((area, point))
    point, area = point[order], area[order]
    first = _firsts(point)
    return point[first], area[first]


def _off_lane(road_map: RoadMap, x, y, missing, rows, headings) -> tuple[np.ndarray, np.ndarray]:
    """Road directions at points in no lane: Scenic's default 0 (outside every road element) and the
    nearest lane's direction (standing in for a road element's own orientation); the caller adds
    Scenic's own pick (a shoulder's direction)."""
    extra_rows = [missing]
    extra = [np.zeros(len(missing))]
    if len(road_map.lanes):
        nearest = road_map._lane_tree.nearest(shapely.points(x[missing], y[missing]))
        extra_rows.append(missing)
        extra.append(road_map.centreline_polylines.direction_at(nearest, x[missing], y[missing]))
    rows = np.concatenate([rows, *extra_rows])
    headings = np.concatenate([headings, *extra])
    order = np.argsort(rows, kind="stable")
    return rows[order], headings[order]


def _segment_distances(start: np.ndarray, end: np.ndarray, px: float, py: float) -> np.ndarray:
    """Distance from (px, py) to each segment start[i]-end[i]."""
    d = end - start
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(
        np.divide(
            (px - start[:, 0]) * d[:, 0] + (py - start[:, 1]) * d[:, 1],
            length2,
            out=np.zeros_like(length2),
            where=length2 > 0,
        ),
        0,
        1,
    )
    return np.hypot(start[:, 0] + t * d[:, 0] - px, start[:, 1] + t * d[:, 1] - py)


def _constant(region: Region, n: int) -> np.ndarray | None:
    """The answer for each of ``n`` rows where the region decides it alone: all True everywhere,
    all False nowhere; None for any other region."""
    if isinstance(region, Everywhere):
        return np.ones(n, dtype=bool)
    if isinstance(region, Nowhere):
        return np.zeros(n, dtype=bool)
    return None


def _box_polygons(x, y, heading, length, width) -> np.ndarray:
    corners = box_corners(x, y, heading, length, width)
    return shapely.polygons(corners)


def _describe(region: Region) -> str:
    return f"a region of kind {type(region).__name__}"


_GEOMETRIES: OrderedDict[int, MapGeometry] = OrderedDict()
