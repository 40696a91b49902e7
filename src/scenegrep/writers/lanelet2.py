"""Lanelet2 maps (``.osm``, Autoware style) written from a road map or an Argoverse 2 vector map.

A :class:`Lanelet2Document` holds nodes, ways and relations as a Lanelet2 map does: equal points
share a node and equal point sequences (either way round) share a way, so a lanelet's successors
and neighbours are the shared points and bounds (what :mod:`scenegrep.readers.lanelet2` reads, as
Lanelet2's routing graph does). Nodes carry ``local_x``/``local_y`` (metres, full precision) and
``lat``/``lon`` 0, as Autoware allows for maps in local metres.

:func:`write_road_map_lanelet2` writes a :class:`~scenegrep.model.RoadMap` as lanelets whose
``centerline`` is the lane's (or area's) own and whose bounds are that centreline (simplified
within :data:`SIMPLIFY_M`) offset along its normals to the edges of its polygon; a bound two
lanes share as neighbours is the mean of their two offsets, and lane bound ends closer than
:data:`SNAP_M` are one node, so the map's successors and neighbours come back. Intersection lanes
get Autoware's ``turn_direction``, speed limits ``speed_limit`` (km/h); crossings, sidewalks and
shoulders become ``crosswalk``, ``walkway`` and ``road_shoulder`` lanelets, curbs ``road_border``
and stop lines ``stop_line`` line strings. Polygons come back as the ring between the bounds, not
the map's own polygons; roads, intersections and the drivable area are what the Lanelet2 reader
derives from the lanelets (the map's own are not written: the format has no primitive for them).
A map with unknown layers is refused: the Lanelet2 map would say they are empty.

:func:`write_av2_lanelet2` writes an AV2 map document (its raw JSON): every lane segment becomes a
lanelet (relation id = the AV2 lane id) whose left and right bounds are the segment's boundaries
as written (``subtype`` road, or ``bicycle_lane``/``bus_lane``); intersection lanes get
``turn_direction`` (from the turn of their left bound). Each pedestrian crossing becomes a
``crosswalk`` lanelet between its two edges; the first also gets a crosswalk regulatory element
with its exact polygon and a stop line.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
import shapely

from ..model import RoadMap
from ..model.lane_shapes import left_normals, resample_polyline
from .atomic import atomic_path

_AV2_KINDS = {"VEHICLE": "road", "BIKE": "bicycle_lane", "BUS": "bus_lane"}
_KINDS = {"vehicle": "road", "bike": "bicycle_lane", "bus": "bus_lane"}
CROSSWALK_ID_BASE = 10**12
"""Relation ids of crosswalk lanelets written from an AV2 map start here (AV2 lane ids are below)."""

SNAP_M = 0.5
"""Bound ends of a road map's lanes closer than this (metres) are written as one node."""

SIMPLIFY_M = 0.02
"""How far (metres) a bound written from a road map may stray from its lane's offset centreline."""

Points = list[tuple[float, float]]


def _points(raw: list[dict[str, float]]) -> Points:
    return [(float(p["x"]), float(p["y"])) for p in raw]


def turn_direction(line: np.ndarray) -> str:
    """Autoware's ``turn_direction`` of a polyline (k x 2, k >= 2): ``left`` or ``right`` where its
    last segment turns more than 30 degrees from its first, else ``straight``."""
    start, end = line[1] - line[0], line[-1] - line[-2]
    angle = np.degrees(np.arctan2(start[0] * end[1] - start[1] * end[0], np.dot(start, end)))
    return "left" if angle > 30 else "right" if angle < -30 else "straight"


class Lanelet2Document:
    """Nodes, ways and relations of a Lanelet2 map being written (see the module docstring)."""

    def __init__(self) -> None:
        self.nodes: dict[tuple[float, float], int] = {}
        self.ways: dict[tuple[int, ...], int] = {}
        self.way_tags: dict[int, dict[str, str]] = {}
        self.way_refs: dict[int, tuple[int, ...]] = {}
        self.relations: list[tuple[int, list[tuple[str, int, str]], dict[str, str]]] = []

    def way(self, points: Points, tags: dict[str, str] | None = None) -> int:
        """The id of the way through ``points``: an untagged way (a thin solid line) is shared with
        an equal one written before, either way round; a tagged one is always new."""
        refs = tuple(self.nodes.setdefault(p, len(self.nodes) + 1) for p in points)
        for key in (refs, refs[::-1]):
            if key in self.ways and tags is None:
                return self.ways[key]
        way_id = len(self.way_tags) + 1
        self.ways.setdefault(refs, way_id)
        self.way_refs[way_id] = refs
        self.way_tags[way_id] = tags or {"type": "line_thin", "subtype": "solid"}
        return way_id

    def lanelet(self, relation_id: int, left: Points, right: Points, tags: dict[str, str], **ways: int) -> None:
        """A lanelet between ``left`` and ``right`` (in its direction of travel), with further
        members by role (``centerline=way_id``)."""
        members = [("way", self.way(left), "left"), ("way", self.way(right), "right")]
        members += [("way", way_id, role) for role, way_id in ways.items()]
        self.relations.append((relation_id, members, {"type": "lanelet", **tags}))

    def text(self) -> str:
        """The map as OSM XML."""
        lines = ["<?xml version='1.0' encoding='UTF-8'?>", "<osm version='0.6' generator='scenegrep'>"]
        for (x, y), node_id in self.nodes.items():
            lines.append(f"  <node id='{node_id}' lat='0' lon='0'>")
            lines += [f"    <tag k='{k}' v='{v!r}'/>" for k, v in (("local_x", x), ("local_y", y), ("ele", 0.0))]
            lines.append("  </node>")
        for way_id in sorted(self.way_tags):
            lines.append(f"  <way id='{way_id}'>")
            lines += [f"    <nd ref='{ref}'/>" for ref in self.way_refs[way_id]]
            lines += [f"    <tag k={quoteattr(k)} v={quoteattr(v)}/>" for k, v in self.way_tags[way_id].items()]
            lines.append("  </way>")
        for relation_id, members, tags in self.relations:
            lines.append(f"  <relation id='{relation_id}'>")
            lines += [f"    <member type='{kind}' ref='{ref}' role='{role}'/>" for kind, ref, role in members]
            lines += [f"    <tag k={quoteattr(k)} v={quoteattr(v)}/>" for k, v in tags.items()]
            lines.append("  </relation>")
        lines.append("</osm>")
        return "\n".join(lines) + "\n"

    def write(self, path: Path) -> Path:
        """Write the map to ``path`` (atomically) and return the path."""
        with atomic_path(path) as temporary:
            temporary.write_text(self.text())
        return path


def _points_of(line: np.ndarray) -> Points:
    return [(float(x), float(y)) for x, y in line]


def _half_widths(centre: np.ndarray, normals: np.ndarray, polygon: shapely.Geometry) -> np.ndarray:
    """How far the lane's polygon reaches to the left and right of each centreline point (k x 2,
    metres), along its normal; an end point is measured 1 cm inside the lane (its normal runs along
    the polygon's end)."""
    tangent = np.gradient(centre, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True).clip(1e-12)
    probe = centre.copy()
    probe[0] += 0.01 * tangent[0]
    probe[-1] -= 0.01 * tangent[-1]
    reach = max(polygon.bounds[2] - polygon.bounds[0], polygon.bounds[3] - polygon.bounds[1])
    rays = shapely.linestrings(np.stack([probe - normals * reach, probe + normals * reach], axis=1))
    widths = np.zeros((len(centre), 2))
    for k, piece in enumerate(shapely.intersection(rays, polygon).tolist()):
        parts = [
            p for p in getattr(piece, "geoms", [piece]) if p.length > 0 and p.distance(shapely.Point(probe[k])) < 1e-6
        ]
        if parts:
            along = (shapely.get_coordinates(parts[0]) - probe[k]) @ normals[k]
            widths[k] = along.max(), -along.min()
    return widths


def _offsets(centreline: np.ndarray, polygon: shapely.Geometry) -> list[np.ndarray]:
    """The left and right bounds of a lane or area: its centreline (simplified by SIMPLIFY_M, which
    drops the centimetre back-steps of Scenic's centrelines at lane-section joins) offset to the
    polygon's edges along its normals."""
    line = shapely.simplify(shapely.linestrings(np.asarray(centreline, np.float64)[:, :2]), SIMPLIFY_M)
    centre = shapely.get_coordinates(line)
    normals = left_normals(centre)
    widths = _half_widths(centre, normals, polygon)
    return [centre + normals * widths[:, :1], centre - normals * widths[:, 1:]]


def _lane_bounds(road_map: RoadMap) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each lane's left and right bound (k x 2, in its direction; see the module docstring): a bound
    shared with a neighbour is one array in both lanes, ends within SNAP_M equal."""
    index = road_map.lane_index
    offsets = [_offsets(lane.centreline, lane.polygon) for lane in road_map.lanes]
    for i, lane in enumerate(road_map.lanes):
        for side, neighbour in ((0, lane.left), (1, lane.right)):
            j = index.get(neighbour.lane) if neighbour is not None else None
            if neighbour is None or j is None or j < i:
                continue
            # the neighbour's bound on our side: its other side when it runs our way, else the same
            other = (1 - side) if neighbour.same_direction else side
            theirs = offsets[j][other] if neighbour.same_direction else offsets[j][other][::-1]
            n = max(len(theirs), len(offsets[i][side]))
            shared = (resample_polyline(offsets[i][side], n) + resample_polyline(theirs, n)) / 2
            offsets[i][side] = shared
            offsets[j][other] = shared if neighbour.same_direction else shared[::-1]
    _snap_ends([line for pair in offsets for line in pair])
    return [(left, right) for left, right in offsets]


def _snap_ends(lines: list[np.ndarray]) -> None:
    """Move the end points of ``lines`` closer than SNAP_M to each other (transitively) onto their
    mean, in place."""
    ends = np.array([line[k] for line in lines for k in (0, -1)])
    points = shapely.points(ends)
    near, other = shapely.STRtree(points).query(points, predicate="dwithin", distance=SNAP_M)
    group = np.arange(len(ends))
    while True:  # each end takes the smallest group of the ends near it, until none changes
        smallest = group.copy()
        np.minimum.at(smallest, near, group[other])
        if np.array_equal(smallest, group):
            break
        group = smallest
    sums = np.zeros_like(ends)
    np.add.at(sums, group, ends)
    means = sums / np.bincount(group, minlength=len(ends))[:, None].clip(1)
    for k, g in enumerate(group.tolist()):
        lines[k // 2][0 if k % 2 == 0 else -1] = means[g]


AREA_SUBTYPES = {"crosswalks": "crosswalk", "sidewalks": "walkway", "shoulders": "road_shoulder"}
"""The lanelet subtype a road map's areas of each layer are written as."""


def road_map_document(road_map: RoadMap) -> Lanelet2Document:
    """A road map as a Lanelet2 map (see the module docstring): lane ``i`` (in the map's order) is
    lanelet ``i + 1``, then the crossings, sidewalks and shoulders (:data:`AREA_SUBTYPES`) in order.
    Raises ValueError for a map with unknown layers (Lanelet2 would say they are empty) or an area
    without a centreline (its bounds are offsets of it)."""
    if road_map.unknown_layers:
        unknown = ", ".join(sorted(road_map.unknown_layers))
        raise ValueError(f"the map does not know its {unknown} layers; a Lanelet2 map would say they are empty")
    document = Lanelet2Document()
    for i, (lane, (left, right)) in enumerate(zip(road_map.lanes, _lane_bounds(road_map))):
        tags = {"subtype": _KINDS[lane.kind], "location": "urban", "one_way": "yes"}
        if lane.is_intersection:
            tags["turn_direction"] = turn_direction(np.asarray(lane.centreline)[:, :2])
        if lane.speed_limit is not None:
            tags["speed_limit"] = f"{lane.speed_limit * 3.6!r}"
        centreline = document.way(_points_of(np.asarray(lane.centreline)[:, :2]), {"type": "centerline"})
        document.lanelet(i + 1, _points_of(left), _points_of(right), tags, centerline=centreline)
    relation_id = len(road_map.lanes)
    for layer, subtype in AREA_SUBTYPES.items():
        for area in getattr(road_map, layer):
            if area.centreline is None:
                raise ValueError(f"{layer} area {area.id} has no centreline; a Lanelet2 map needs its bounds")
            relation_id += 1
            left, right = _offsets(area.centreline, area.polygon)
            centreline = document.way(_points_of(np.asarray(area.centreline)[:, :2]), {"type": "centerline"})
            tags = {"subtype": subtype, "location": "urban", "one_way": "no"}
            document.lanelet(relation_id, _points_of(left), _points_of(right), tags, centerline=centreline)
    for curb in road_map.curbs:
        document.way(_points_of(curb), {"type": "road_border"})
    for line in road_map.stop_lines:
        document.way(_points_of(line), {"type": "stop_line"})
    return document


def write_road_map_lanelet2(road_map: RoadMap, path: Path) -> Path:
    """Write ``road_map`` as the Lanelet2 map :func:`road_map_document` makes at ``path``."""
    return road_map_document(road_map).write(path)


def write_av2_lanelet2(av2_map: dict[str, Any], path: Path) -> Path:
    """Write the AV2 map document ``av2_map`` as a Lanelet2 map at ``path`` (see the module docstring)."""
    document = Lanelet2Document()
    for seg in av2_map["lane_segments"].values():
        left, right = _points(seg["left_lane_boundary"]), _points(seg["right_lane_boundary"])
        tags = {"subtype": _AV2_KINDS[seg["lane_type"]], "location": "urban", "one_way": "yes"}
        if seg["is_intersection"]:
            tags["turn_direction"] = turn_direction(np.array(left))
        document.lanelet(int(seg["id"]), left, right, tags)
    for k, crossing in enumerate(av2_map["pedestrian_crossings"].values()):
        edge1, edge2 = _points(crossing["edge1"]), _points(crossing["edge2"])
        lanelet_id = CROSSWALK_ID_BASE + k
        document.lanelet(lanelet_id, edge1, edge2, {"subtype": "crosswalk", "one_way": "no"})
        if k == 0:
            ring = document.way(edge1 + edge2[::-1], {"type": "crosswalk_polygon", "area": "yes"})
            stop = document.way(
                [edge1[0], edge2[0]] if edge1[0] != edge2[0] else [edge1[0], edge2[-1]], {"type": "stop_line"}
            )
            members = [
                ("way", stop, "ref_line"),
                ("way", ring, "crosswalk_polygon"),
                ("relation", lanelet_id, "refers"),
            ]
            document.relations.append(
                (2 * CROSSWALK_ID_BASE, members, {"type": "regulatory_element", "subtype": "crosswalk"})
            )
    return document.write(path)
