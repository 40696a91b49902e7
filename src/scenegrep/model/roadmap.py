"""The road map: lanes with topology, roads, intersections, crosswalks, sidewalks,
curbs and drivable area, with vectorised point queries over R-trees.

Coordinates are metres in the map frame of the traces that use it; directions
are Scenic headings (see :mod:`scenegrep.model.geometry`). A lane's centreline
runs in its direction of travel. Point queries take arrays of x and y and answer
for all points at once; the R-trees (shapely STRtrees) are built on first use.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from collections.abc import Iterable

import numpy as np
import shapely
from shapely import STRtree
from shapely.geometry.base import BaseGeometry

from .geometry import heading_difference
from .lane_shapes import line_strings
from .polylines import Polylines


@dataclass(frozen=True)
class LaneNeighbour:
    """An adjacent lane and whether its traffic runs the same way."""

    lane: str
    same_direction: bool


@dataclass(frozen=True, eq=False)
class Lane:
    """A lane: polygon, centreline (k x 2, in travel direction) and topology.

    ``kind`` is ``vehicle``, ``bike`` or ``bus``; ``speed_limit`` is in m/s when known.
    """

    id: str
    polygon: BaseGeometry
    centreline: np.ndarray
    road: str | None = None
    is_intersection: bool = False
    successors: tuple[str, ...] = ()
    predecessors: tuple[str, ...] = ()
    left: LaneNeighbour | None = None
    right: LaneNeighbour | None = None
    kind: str = "vehicle"
    speed_limit: float | None = None


@dataclass(frozen=True, eq=False)
class Area:
    """A polygonal map element (road, intersection, crosswalk, sidewalk) and the lanes it holds.

    ``centreline`` (k x 2, metres) gives a sidewalk's or crosswalk's direction where the map's
    format has one (OpenDRIVE through Scenic): Scenic orients the element along the segment of
    its centreline nearest to a point; None where the format gives none (direction unknown).
    """

    id: str
    polygon: BaseGeometry
    lanes: tuple[str, ...] = ()
    centreline: np.ndarray | None = None


REGION_NAMES = ("lane", "road", "intersection", "crossing", "sidewalk", "drivable")
"""Region names accepted by :meth:`RoadMap.contains`; Scenic's driving-domain names."""

OPTIONAL_LAYERS = ("crossing", "sidewalk", "curb", "shoulder")
"""Layers a map format may not publish (see :attr:`RoadMap.unknown_layers`); lanes, roads,
intersections and the drivable area are published by every format."""


@dataclass(frozen=True, eq=False)
class RoadMap:
    """A road network; see the module docstring. ``curbs`` are polylines (k x 2 arrays).
    ``shoulders`` are the road shoulders where a map separates them from the drivable area
    (OpenDRIVE); a map whose ``drivable_area`` is given includes its shoulders there.

    ``unknown_layers`` (a subset of :data:`OPTIONAL_LAYERS`) are the layers the map's format does
    not publish: their elements are *unknown*, not absent. Every other layer holds exactly the
    elements given, so a published layer with no elements is *empty*. Readers state it per format;
    a map built in code publishes every layer.

    ``stop_lines`` are the stop lines (k x 2 polylines, metres) of a map that draws them (Lanelet2);
    they are held and counted, and no query reads them yet."""

    name: str
    lanes: tuple[Lane, ...]
    roads: tuple[Area, ...] = ()
    intersections: tuple[Area, ...] = ()
    crosswalks: tuple[Area, ...] = ()
    sidewalks: tuple[Area, ...] = ()
    curbs: tuple[np.ndarray, ...] = ()
    drivable_area: BaseGeometry | None = None
    source: str | None = field(default=None, compare=False)
    shoulders: tuple[Area, ...] = ()
    unknown_layers: frozenset[str] = frozenset()
    stop_lines: tuple[np.ndarray, ...] = ()

    def __post_init__(self) -> None:
        odd = set(self.unknown_layers) - set(OPTIONAL_LAYERS)
        if odd:
            raise ValueError(f"unknown_layers names {sorted(odd)}; only {', '.join(OPTIONAL_LAYERS)} may be unknown")

    def publishes(self, layer: str) -> bool:
        """Whether the map's format publishes ``layer`` (then its elements here are all there are)."""
        return layer not in self.unknown_layers

    def orients(self, layer: str) -> bool:
        """Whether the map gives the direction of every element of ``layer`` (``sidewalk`` or
        ``crossing``): the layer is published and each of its elements has a centreline."""
        areas = {"sidewalk": self.sidewalks, "crossing": self.crosswalks}[layer]
        return self.publishes(layer) and all(a.centreline is not None for a in areas)

    # ------------------------------------------------------------------ lookup tables
    @cached_property
    def lane_index(self) -> dict[str, int]:
        """Lane id -> position in :attr:`lanes`."""
        return {lane.id: i for i, lane in enumerate(self.lanes)}

    @cached_property
    def lane_polygons(self) -> np.ndarray:
        return np.array([lane.polygon for lane in self.lanes], dtype=object)

    @cached_property
    def lane_centrelines(self) -> np.ndarray:
        return line_strings([lane.centreline for lane in self.lanes])

    @cached_property
    def centreline_polylines(self) -> Polylines:
        """The lane centrelines as :class:`Polylines` (direction queries)."""
        return Polylines([lane.centreline for lane in self.lanes])

    @cached_property
    def curb_polylines(self) -> Polylines:
        """The curbs as :class:`Polylines`."""
        return Polylines(list(self.curbs))

    @cached_property
    def lane_is_intersection(self) -> np.ndarray:
        return np.array([lane.is_intersection for lane in self.lanes], dtype=bool)

    @cached_property
    def _lane_tree(self) -> STRtree:
        """An R-tree of the lane polygons, prepared (GEOS indexes each one once, for the many
        point-in-lane tests made while walking: the same answers, faster)."""
        shapely.prepare(self.lane_polygons)
        return STRtree(self.lane_polygons)

    @cached_property
    def _region_trees(self) -> dict[str, STRtree]:
        groups = {
            "road": [a.polygon for a in self.roads],
            "intersection": [a.polygon for a in self.intersections],
            "crossing": [a.polygon for a in self.crosswalks],
            "sidewalk": [a.polygon for a in self.sidewalks],
            "drivable": [self.drivable] if not self.drivable.is_empty else [],
        }
        return {name: STRtree(np.array(geoms, dtype=object)) for name, geoms in groups.items()}

    @cached_property
    def _prepared_drivable(self) -> BaseGeometry:
        shapely.prepare(self.drivable)
        return self.drivable

    @cached_property
    def drivable(self) -> BaseGeometry:
        """The drivable area; the union of the lane polygons when the map gives none."""
        if self.drivable_area is not None:
            return self.drivable_area
        return shapely.union_all(self.lane_polygons) if self.lanes else shapely.Polygon()

    def bounds(self) -> tuple[float, float, float, float]:
        """(min x, min y, max x, max y) of all lanes and areas, in metres."""
        geoms = list(self.lane_polygons) + [
            a.polygon for a in self.roads + self.intersections + self.crosswalks + self.sidewalks
        ]
        return tuple(shapely.total_bounds(np.array(geoms, dtype=object)).tolist())  # type: ignore[return-value]

    # ------------------------------------------------------------------ point queries
    def lanes_containing(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """All (point, lane) pairs where point i lies in lane j (boundary included).

        Returns two int arrays (point indices, lane indices), sorted by point.
        """
        points = shapely.points(np.atleast_1d(x), np.atleast_1d(y))
        if not self.lanes:
            return np.zeros(0, np.intp), np.zeros(0, np.intp)
        point_idx, lane_idx = tree_containing(self._lane_tree, points)
        order = np.lexsort((lane_idx, point_idx))
        return point_idx[order], lane_idx[order]

    def lane_at(
        self,
        x: np.ndarray,
        y: np.ndarray,
        heading: np.ndarray | None = None,
        *,
        pairs: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> np.ndarray:
        """Index of the lane each point is in (-1 for none).

        Where lanes overlap (intersections), the lane whose direction at the point is
        closest to ``heading`` (radians) wins when a heading is given, else the lane
        whose centreline is nearest. ``pairs`` is :meth:`lanes_containing` of the same
        points when the caller has it already (here and in the other point queries).
        """
        x, y = np.atleast_1d(np.asarray(x, dtype=float)), np.atleast_1d(np.asarray(y, dtype=float))
        result = np.full(len(x), -1, dtype=np.intp)
        point_idx, lane_idx = self.lanes_containing(x, y) if pairs is None else pairs
        if len(point_idx) == 0:
            return result
        if heading is None:
            cost = shapely.distance(self.lane_centrelines[lane_idx], shapely.points(x[point_idx], y[point_idx]))
        else:
            directions = self._directions(lane_idx, x[point_idx], y[point_idx])
            cost = np.abs(heading_difference(np.atleast_1d(heading)[point_idx], directions))
        order = np.lexsort((cost, point_idx))
        first = np.ones(len(order), dtype=bool)
        first[1:] = point_idx[order][1:] != point_idx[order][:-1]
        result[point_idx[order][first]] = lane_idx[order][first]
        return result

    def lane_direction_at(self, x: np.ndarray, y: np.ndarray, lane: np.ndarray | None = None) -> np.ndarray:
        """Direction of travel (heading, radians) at each point: the direction of the centreline
        of ``lane`` (or of the lane found by :meth:`lane_at`) at the point (see :meth:`_directions`);
        NaN off-lane."""
        x, y = np.atleast_1d(np.asarray(x, dtype=float)), np.atleast_1d(np.asarray(y, dtype=float))
        lane = self.lane_at(x, y) if lane is None else np.atleast_1d(lane)
        out = np.full(len(x), np.nan)
        on = lane >= 0
        out[on] = self._directions(lane[on], x[on], y[on])
        return out

    def nominal_directions_at(self, x: float, y: float) -> list[float]:
        """Headings of every lane containing the point (several inside intersections)."""
        _, lanes = self.lanes_containing(np.array([x]), np.array([y]))
        return self._directions(lanes, np.full(len(lanes), x), np.full(len(lanes), y)).tolist()

    def in_intersection(
        self, x: np.ndarray, y: np.ndarray, *, pairs: tuple[np.ndarray, np.ndarray] | None = None
    ) -> np.ndarray:
        """Whether each point lies in an intersection area or in an intersection lane."""
        inside = self.contains("intersection", x, y)
        point_idx, lane_idx = self.lanes_containing(x, y) if pairs is None else pairs
        inside[point_idx[self.lane_is_intersection[lane_idx]]] = True
        return inside

    def contains(
        self, region: str, x: np.ndarray, y: np.ndarray, *, pairs: tuple[np.ndarray, np.ndarray] | None = None
    ) -> np.ndarray:
        """Whether each point lies in the named region (one of :data:`REGION_NAMES`), boundary included."""
        x, y = np.atleast_1d(np.asarray(x, dtype=float)), np.atleast_1d(np.asarray(y, dtype=float))
        inside = np.zeros(len(x), dtype=bool)
        if region == "lane" or (region == "drivable" and self.drivable_area is None):
            inside[(self.lanes_containing(x, y) if pairs is None else pairs)[0]] = True
            return inside
        if region == "drivable":
            return shapely.intersects_xy(self._prepared_drivable, x, y)
        if region not in self._region_trees:
            raise KeyError(f"unknown map region {region!r}; known: {', '.join(REGION_NAMES)}")
        tree = self._region_trees[region]
        if len(tree.geometries):
            inside[tree.query(shapely.points(x, y), predicate="intersects")[0]] = True
        return inside

    def _directions(self, lane_idx: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Direction of travel of lane ``lane_idx[i]`` at point i: the heading of its centreline's
        segment nearest to the point by projection (Scenic's rule)."""
        return self.centreline_polylines.direction_at(lane_idx, x, y)

    # ------------------------------------------------------------------ comparison
    def equals(self, other: object) -> bool:
        """Element-by-element equality with exactly equal coordinates."""
        if not isinstance(other, RoadMap) or self.name != other.name:
            return False
        if self.unknown_layers != other.unknown_layers:
            return False
        pairs = [
            (self.lanes, other.lanes),
            (self.roads, other.roads),
            (self.intersections, other.intersections),
            (self.crosswalks, other.crosswalks),
            (self.sidewalks, other.sidewalks),
            (self.shoulders, other.shoulders),
        ]
        lines = [(self.curbs, other.curbs), (self.stop_lines, other.stop_lines)]
        if any(len(a) != len(b) for a, b in pairs + lines):
            return False
        if not all(_same_element(x, y) for a, b in pairs for x, y in zip(a, b)):
            return False
        if not all(np.array_equal(x, y) for a, b in lines for x, y in zip(a, b)):
            return False
        if (self.drivable_area is None) != (other.drivable_area is None):
            return False
        return self.drivable_area is None or bool(shapely.equals_exact(self.drivable_area, other.drivable_area, 0.0))

    # ------------------------------------------------------------------ cropping
    def crop(self, x: float, y: float, radius: float) -> RoadMap:
        """The elements within ``radius`` metres of (x, y); topology links to dropped lanes are kept
        as ids, so a cropped lane still names its successors."""
        disc = shapely.Point(x, y).buffer(radius)

        def near(items: Iterable[Area]) -> tuple[Area, ...]:
            return tuple(a for a in items if a.polygon.intersects(disc))

        lanes = tuple(self.lanes[i] for i in self._lane_tree.query(disc, predicate="intersects").tolist())
        lanes = tuple(sorted(lanes, key=lambda lane: self.lane_index[lane.id]))
        curbs, stop_lines = (
            tuple(c for c in lines if shapely.linestrings(c).intersects(disc))
            for lines in (self.curbs, self.stop_lines)
        )
        drivable = None if self.drivable_area is None else self.drivable_area.intersection(disc)
        return RoadMap(
            self.name,
            lanes,
            near(self.roads),
            near(self.intersections),
            near(self.crosswalks),
            near(self.sidewalks),
            curbs,
            drivable,
            self.source,
            near(self.shoulders),
            self.unknown_layers,
            stop_lines,
        )


def tree_containing(tree: STRtree, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(point, geometry) pairs where the tree's geometry intersects the point (shapely points),
    as ``tree.query(points, predicate="intersects")`` finds them: the R-tree's box candidates
    tested against the tree's geometries, prepared by its builder (the tree's own predicate
    prepares the points instead, and tests each polygon's every edge)."""
    point, found = tree.query(points)
    hit = shapely.intersects(tree.geometries[found], points[point])
    return point[hit], found[hit]


def _same_element(a: Lane | Area, b: Lane | Area) -> bool:
    """Equality of two lanes or two areas: fields equal, geometry coordinates exactly equal."""
    if type(a) is not type(b) or not shapely.equals_exact(a.polygon, b.polygon, 0.0):
        return False
    for name in a.__dataclass_fields__:
        mine, theirs = getattr(a, name), getattr(b, name)
        if name == "polygon":
            continue
        if isinstance(mine, np.ndarray) or isinstance(theirs, np.ndarray):
            if mine is None or theirs is None or not np.array_equal(mine, theirs):
                return False
        elif mine != theirs:
            return False
    return True
