"""Lanelet2 maps (``.osm``, as Autoware uses them) read into the road map.

The tagging scheme is Lanelet2's (``lanelet2_core/doc``: LaneletPrimitives, LaneletAndAreaTagging,
LinestringTagging) with Autoware's extensions (``autoware_lanelet2_extension/docs`` and the
Autoware vector map requirements). A lanelet is a relation ``type=lanelet`` with one ``left`` and
one ``right`` bound (ways) and optionally a ``centerline``; its ``subtype`` (``road`` when absent)
says who uses it:

- lanes: ``road``, ``highway``, ``play_street``, ``emergency_lane``, ``exit`` (kind ``vehicle``),
  ``bus_lane`` (``bus``), ``bicycle_lane`` (``bike``); ``speed_limit`` (km/h unless a unit
  ``km/h``, ``mph`` or ``m/s`` follows) in m/s;
- crossings: ``crosswalk`` lanelets (their centreline, the walking direction, orients them). An
  Autoware crosswalk regulatory element (``subtype=crosswalk``) with a ``crosswalk_polygon``
  gives the exact area of the crosswalk lanelet it ``refers`` to (a crossing of its own, without
  direction, when it refers to none);
- sidewalks: ``walkway``, ``shared_walkway`` and ``stairs`` lanelets, the parts of a way for
  pedestrians (Lanelet2's table), oriented by their centrelines;
- shoulders: Autoware's roadside lanes, ``road_shoulder`` and ``pedestrian_lane``;
- curbs: line strings ``type=curbstone`` or ``road_border`` (the edges of the road);
- stop lines: line strings ``type=stop_line`` (what traffic light, sign and crosswalk regulatory
  elements name as their ``ref_line``).

Lanelets of other subtypes, and Lanelet2 areas (multipolygons), are not read. Every optional
layer can be expressed in the format, so none is unknown: a map without, say, walkways has an
empty sidewalk layer.

Direction: the bounds are aligned as Lanelet2 aligns them when it loads a map
(``geometry::align``): the left bound is reversed unless the right bound's middle point lies to
its right, the right bound unless the left's lies to its left; the lanelet runs along the aligned
bounds. Its polygon is the ring between them, its centreline the ``centerline`` way (reversed if
it runs backwards) or the mean of the bounds (:func:`~scenegrep.model.lane_shapes.centreline_between`).
Topology as in Lanelet2's routing graph: lane B succeeds lane A when A's aligned bounds end on the
points (node ids) where B's begin; B is A's left (right) neighbour when they share A's left (right)
bound way, in the same direction when B holds it as its right (left) bound running the same way.

Intersections: plain Lanelet2 has none; Autoware tags every lanelet in an intersection with
``turn_direction`` (and, in newer maps, ``intersection_area`` naming a polygon ``type=intersection_area``).
A lane with either tag is an intersection lane; an ``intersection_area`` polygon is an intersection
holding the lanes that name it, and the other intersection lanes form intersections as connected
unions (:func:`~scenegrep.model.lane_topology.derive_intersections`). Roads are the laterally
linked groups of the other lanes; the drivable area is the union of the lanes.

Coordinates: Autoware maps carry metric ``local_x``/``local_y`` tags on every node; they are used
when every node has both, else every node's ``lat``/``lon`` is projected to Autoware's MGRS-local
metres (:mod:`.utm`), which is the map frame of Autoware's default projector.
"""

from __future__ import annotations

import mmap
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import shapely

from ..errors import UserError, at
from ..model import Area, Lane, LaneNeighbour, RoadMap
from ..model.lane_shapes import centreline_between, polygon_between
from ..model.lane_topology import derive_intersections, derive_roads
from . import map_cache
from .osm_xml import Element, OsmDocument, read_osm
from .utm import to_mgrs_local
from ..wording import counted

FORMAT = "lanelet2"
CONVERSION_VERSION = 1
"""Bumped whenever the conversion changes, so cached maps (:mod:`.map_cache`) are rebuilt."""
UNKNOWN_LAYERS: frozenset[str] = frozenset()
"""The format expresses every optional layer (see the module docstring)."""
LANE_KINDS = {
    "road": "vehicle",
    "highway": "vehicle",
    "play_street": "vehicle",
    "emergency_lane": "vehicle",
    "exit": "vehicle",
    "bus_lane": "bus",
    "bicycle_lane": "bike",
}
CROSSWALK_SUBTYPES = frozenset({"crosswalk"})
SIDEWALK_SUBTYPES = frozenset({"walkway", "shared_walkway", "stairs"})
SHOULDER_SUBTYPES = frozenset({"road_shoulder", "pedestrian_lane"})
CURB_TYPES = frozenset({"curbstone", "road_border"})
MAX_COORDINATE_M = 1e8
"""Coordinates beyond this many metres (a thousand times the Earth's radius) are refused."""
_SPEED_UNITS = {"": 1 / 3.6, "km/h": 1 / 3.6, "kmh": 1 / 3.6, "mph": 0.44704, "m/s": 1.0}
_SPEED = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?)\s*([a-z/]*)\s*$")


def is_lanelet_map(path: Path) -> bool:
    """Whether an ``.osm`` file is OSM XML holding a lanelet (a ``type=lanelet`` tag anywhere)."""
    with open(path, "rb") as handle:
        if b"<osm" not in handle.read(4096) or Path(path).stat().st_size == 0:
            return False
        with mmap.mmap(handle.fileno(), 0, access=mmap.ACCESS_READ) as data:
            return data.find(b'v="lanelet"') >= 0 or data.find(b"v='lanelet'") >= 0


@dataclass
class _Bounds:
    """A lanelet's aligned bounds: node ids and coordinates (k x 2) of each."""

    left_ids: list[str]
    right_ids: list[str]
    left: np.ndarray
    right: np.ndarray
    left_way: str
    right_way: str
    left_reversed: bool
    right_reversed: bool


class _Reader:
    """Turns an :class:`OsmDocument` into a :class:`RoadMap` (see the module docstring)."""

    def __init__(self, path: Path, doc: OsmDocument):
        self.path, self.doc = path, doc
        self.index = {node_id: i for i, node_id in enumerate(doc.nodes)}
        self.xy = self._coordinates()

    def fail(self, element: Element, message: str) -> UserError:
        return UserError(message, at(self.path, element.line))

    # ------------------------------------------------------------------ coordinates
    def _numbers(self, key: str, from_tags: bool) -> np.ndarray:
        values = np.empty(len(self.doc.nodes))
        for i, (node_id, node) in enumerate(self.doc.nodes.items()):
            text = (node.tags if from_tags else node.attributes).get(key)
            try:
                values[i] = float(text)  # type: ignore[arg-type]
            except (TypeError, ValueError):
                raise self.fail(node, f"node {node_id}: {key} is {text!r}, not a number") from None
            if not np.isfinite(values[i]) or abs(values[i]) > MAX_COORDINATE_M:
                raise self.fail(node, f"node {node_id}: {key} {text!r} is not a finite coordinate")
        return values

    def _coordinates(self) -> np.ndarray:
        nodes = self.doc.nodes.values()
        local = [("local_x" in n.tags and "local_y" in n.tags) for n in nodes]
        if all(local):
            return np.column_stack([self._numbers("local_x", True), self._numbers("local_y", True)])
        if any(local):  # Autoware may leave lat/lon as placeholders beside local_x/local_y
            node_id, node = next((i, n) for (i, n), has in zip(self.doc.nodes.items(), local) if not has)
            raise self.fail(node, f"node {node_id} has no local_x/local_y while other nodes have them")
        if not nodes:
            return np.zeros((0, 2))
        lat, lon = self._numbers("lat", False), self._numbers("lon", False)
        try:
            return np.column_stack(to_mgrs_local(lat, lon))
        except ValueError as exc:
            raise UserError(f"cannot project the nodes' lat/lon to metres: {exc}", at(self.path)) from None

    # ------------------------------------------------------------------ primitives
    def way(self, way_id: str, owner: Element, what: str, min_points: int = 2) -> tuple[list[str], np.ndarray]:
        """The node ids and coordinates of a way named by ``owner`` as ``what``."""
        way = self.doc.ways.get(way_id)
        if way is None:
            raise self.fail(owner, f"{what} is way {way_id}, which the map does not hold")
        try:
            rows = [self.index[ref] for ref in way.refs]
        except KeyError as exc:
            raise self.fail(way, f"way {way_id} refers to node {exc.args[0]}, which the map does not hold") from None
        if len(rows) < min_points:
            raise self.fail(
                way, f"way {way_id} ({what}) has {counted(len(rows), 'node')}; it needs at least {min_points}"
            )
        return list(way.refs), self.xy[rows]

    def member(self, relation: Element, relation_id: str, role: str, required: bool = True) -> str | None:
        """The id of the one way member with ``role`` (None when optional and absent)."""
        found = [ref for kind, ref, r in relation.members if r == role and kind == "way"]
        if len(found) > 1 or (required and not found):
            count = "several" if found else "no"
            raise self.fail(relation, f"relation {relation_id} has {count} {role!r} way members; it needs one")
        return found[0] if found else None

    def bounds(self, relation_id: str, relation: Element) -> _Bounds:
        left_way = self.member(relation, relation_id, "left")
        right_way = self.member(relation, relation_id, "right")
        left_ids, left = self.way(left_way, relation, f"the left bound of lanelet {relation_id}")  # type: ignore[arg-type]
        right_ids, right = self.way(right_way, relation, f"the right bound of lanelet {relation_id}")  # type: ignore[arg-type]
        flip_left = _signed_distance(left, _middle(right)) >= 0
        if flip_left:
            left_ids, left = left_ids[::-1], left[::-1]
        flip_right = _signed_distance(right, _middle(left)) <= 0
        if flip_right:
            right_ids, right = right_ids[::-1], right[::-1]
        return _Bounds(left_ids, right_ids, left, right, left_way, right_way, flip_left, flip_right)  # type: ignore[arg-type]

    def centreline(self, relation_id: str, relation: Element, bounds: _Bounds) -> np.ndarray:
        way_id = self.member(relation, relation_id, "centerline", required=False)
        if way_id is None:
            return centreline_between(bounds.left, bounds.right)
        _, centre = self.way(way_id, relation, f"the centerline of lanelet {relation_id}")
        start = (bounds.left[0] + bounds.right[0]) / 2
        return centre[::-1] if np.hypot(*(centre[-1] - start)) < np.hypot(*(centre[0] - start)) else centre

    def speed_limit(self, relation_id: str, relation: Element) -> float | None:
        text = relation.tags.get("speed_limit")
        if text is None:
            return None
        match = _SPEED.match(text.lower())
        if match is None or match.group(2) not in _SPEED_UNITS:
            raise self.fail(
                relation, f"lanelet {relation_id}: speed_limit {text!r} is not a speed (e.g. '50' or '30 mph')"
            )
        return float(match.group(1)) * _SPEED_UNITS[match.group(2)]

    # ------------------------------------------------------------------ the map
    def read(self) -> RoadMap:
        lanelets = {rid: r for rid, r in self.doc.relations.items() if r.tags.get("type") == "lanelet"}
        bounds = {rid: self.bounds(rid, r) for rid, r in lanelets.items()}
        subtype = {rid: r.tags.get("subtype", "road") for rid, r in lanelets.items()}
        lanes_ids = [rid for rid in lanelets if subtype[rid] in LANE_KINDS]
        lanes = _linked(
            [
                Lane(
                    rid,
                    polygon_between(bounds[rid].left, bounds[rid].right),
                    self.centreline(rid, lanelets[rid], bounds[rid]),
                    is_intersection="turn_direction" in lanelets[rid].tags or "intersection_area" in lanelets[rid].tags,
                    kind=LANE_KINDS[subtype[rid]],
                    speed_limit=self.speed_limit(rid, lanelets[rid]),
                )
                for rid in lanes_ids
            ],
            bounds,
        )

        def areas(subtypes: frozenset[str]) -> list[Area]:
            return [
                Area(
                    rid,
                    polygon_between(bounds[rid].left, bounds[rid].right),
                    centreline=self.centreline(rid, lanelets[rid], bounds[rid]),
                )
                for rid in lanelets
                if subtype[rid] in subtypes
            ]

        return RoadMap(
            self.path.stem,
            tuple(lanes),
            derive_roads(lanes),
            self.intersections(lanes, lanelets),
            self.crosswalks(areas(CROSSWALK_SUBTYPES)),
            tuple(areas(SIDEWALK_SUBTYPES)),
            tuple(self.lines(CURB_TYPES)),
            source=str(self.path),
            shoulders=tuple(areas(SHOULDER_SUBTYPES)),
            unknown_layers=UNKNOWN_LAYERS,
            stop_lines=tuple(self.lines(frozenset({"stop_line"}))),
        )

    def lines(self, types: frozenset[str]) -> list[np.ndarray]:
        return [
            self.way(way_id, way, f"{way.tags['type']} way {way_id}")[1]
            for way_id, way in self.doc.ways.items()
            if way.tags.get("type") in types
        ]

    def polygon(self, way_id: str, owner: Element, what: str) -> shapely.Geometry:
        return shapely.make_valid(shapely.Polygon(self.way(way_id, owner, what, min_points=3)[1]))

    def crosswalks(self, lanelet_areas: list[Area]) -> tuple[Area, ...]:
        """Crosswalk lanelets, with the exact polygons their crosswalk regulatory elements give."""
        by_id = {a.id: a for a in lanelet_areas}
        extra = []
        for rid, relation in self.doc.relations.items():
            if relation.tags.get("type") != "regulatory_element" or relation.tags.get("subtype") != "crosswalk":
                continue
            way_id = self.member(relation, rid, "crosswalk_polygon", required=False)
            if way_id is None:
                continue
            polygon = self.polygon(way_id, relation, f"the crosswalk_polygon of regulatory element {rid}")
            refers = [ref for kind, ref, role in relation.members if role == "refers" and ref in by_id]
            for ref in refers:
                by_id[ref] = replace(by_id[ref], polygon=polygon)
            if not refers:
                extra.append(Area(f"crosswalk{rid}", polygon))
        return tuple(by_id.values()) + tuple(extra)

    def intersections(self, lanes: list[Lane], lanelets: dict[str, Element]) -> tuple[Area, ...]:
        """``intersection_area`` polygons holding the lanes that name them, then the connected
        unions of the other intersection lanes."""
        named: dict[str, list[str]] = {}
        for lane in lanes:
            area_id = lanelets[lane.id].tags.get("intersection_area")
            if area_id is not None:
                named.setdefault(area_id, []).append(lane.id)
        found = []
        for way_id, way in self.doc.ways.items():
            if way.tags.get("type") == "intersection_area":
                polygon = self.polygon(way_id, way, f"intersection_area way {way_id}")
                found.append(Area(f"intersection_area{way_id}", polygon, tuple(named.pop(way_id, ()))))
        held = {lane for area in found for lane in area.lanes}
        derived = derive_intersections([lane for lane in lanes if lane.id not in held])
        return tuple(found) + derived


def _middle(line: np.ndarray) -> np.ndarray:
    """Lanelet2's middle point of a line string: its middle vertex, or its end points' mean."""
    return line[len(line) // 2] if len(line) > 2 else (line[0] + line[-1]) / 2


def _signed_distance(line: np.ndarray, point: np.ndarray) -> float:
    """The distance of ``point`` from the polyline ``line`` (k x 2), positive on its left."""
    a, b = line[:-1], line[1:]
    d = b - a
    length2 = (d * d).sum(axis=1)
    t = np.clip(np.divide(((point - a) * d).sum(axis=1), length2, out=np.zeros(len(a)), where=length2 > 0), 0, 1)
    nearest = a + t[:, None] * d
    k = int(np.argmin(np.hypot(*(point - nearest).T)))
    cross = d[k, 0] * (point[1] - a[k, 1]) - d[k, 1] * (point[0] - a[k, 0])
    return float(np.copysign(np.hypot(*(point - nearest[k])), cross))


def _linked(lanes: list[Lane], bounds: dict[str, _Bounds]) -> list[Lane]:
    """Lanes with successors, predecessors and neighbours from shared points and bounds."""
    starts: dict[tuple[str, str], list[str]] = {}
    for lane in lanes:
        b = bounds[lane.id]
        starts.setdefault((b.left_ids[0], b.right_ids[0]), []).append(lane.id)
    successors = {
        lane.id: tuple(
            s for s in starts.get((bounds[lane.id].left_ids[-1], bounds[lane.id].right_ids[-1]), ()) if s != lane.id
        )
        for lane in lanes
    }
    predecessors: dict[str, list[str]] = {lane.id: [] for lane in lanes}
    for lane_id, after in successors.items():
        for other in after:
            predecessors[other].append(lane_id)
    holders: dict[str, list[tuple[str, str, bool]]] = {}
    for lane in lanes:
        b = bounds[lane.id]
        holders.setdefault(b.left_way, []).append((lane.id, "left", b.left_reversed))
        holders.setdefault(b.right_way, []).append((lane.id, "right", b.right_reversed))

    def neighbour(lane_id: str, side: str) -> LaneNeighbour | None:
        b = bounds[lane_id]
        way, reversed_here = (b.left_way, b.left_reversed) if side == "left" else (b.right_way, b.right_reversed)
        for other, other_side, reversed_there in holders[way]:
            if other != lane_id:
                return LaneNeighbour(other, other_side != side and reversed_here == reversed_there)
        return None

    return [
        replace(
            lane,
            successors=successors[lane.id],
            predecessors=tuple(predecessors[lane.id]),
            left=neighbour(lane.id, "left"),
            right=neighbour(lane.id, "right"),
        )
        for lane in lanes
    ]


def convert(path: str | Path) -> RoadMap:
    """The road map of a Lanelet2 ``.osm`` file (see the module docstring); a malformed map is a
    one-line :class:`UserError` naming the file and, where there is one, the line at fault."""
    path = Path(path)
    return _Reader(path, read_osm(path)).read()


def read_map(path: str | Path) -> RoadMap:
    """:func:`convert` through the cache of converted maps (:mod:`.map_cache`): a city's map takes
    seconds to convert, a tenth of that to load once converted."""
    path = Path(path)
    return map_cache.through_cache(path, f"lanelet2-v{CONVERSION_VERSION}", lambda: convert(path))
