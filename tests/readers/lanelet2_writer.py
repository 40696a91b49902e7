"""Write an Argoverse 2 vector map (its raw JSON document) as a Lanelet2 ``.osm`` map, Autoware style.

Every lane segment becomes a lanelet (relation id = the AV2 lane id) whose left and right bounds
are the segment's boundaries as written (``subtype`` road, or ``bicycle_lane``/``bus_lane``);
intersection lanes get Autoware's ``turn_direction`` (from the turn of their centreline). Equal
points share a node and equal boundaries (either way round) share a way, as in a Lanelet2 map, so
successors and neighbours are the shared points and bounds. Each pedestrian crossing becomes a
``crosswalk`` lanelet between its two edges; the first also gets a crosswalk regulatory element
with its exact polygon and a stop line. Nodes carry ``local_x``/``local_y`` (full precision) and
``lat``/``lon`` 0, as Autoware allows for maps in local metres.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

_KINDS = {"VEHICLE": "road", "BIKE": "bicycle_lane", "BUS": "bus_lane"}
CROSSWALK_ID_BASE = 10**12
"""Relation ids of crosswalk lanelets start here (AV2 lane ids are below)."""


def _points(raw: list[dict[str, float]]) -> list[tuple[float, float]]:
    return [(float(p["x"]), float(p["y"])) for p in raw]


def _turn(points: list[tuple[float, float]]) -> str:
    """Autoware's turn_direction of a bound: left or right where it turns more than 30 degrees."""
    xy = np.array(points)
    start, end = xy[1] - xy[0], xy[-1] - xy[-2]
    angle = np.degrees(np.arctan2(start[0] * end[1] - start[1] * end[0], np.dot(start, end)))
    return "left" if angle > 30 else "right" if angle < -30 else "straight"


class _Osm:
    def __init__(self) -> None:
        self.nodes: dict[tuple[float, float], int] = {}
        self.ways: dict[tuple[int, ...], int] = {}
        self.way_tags: dict[int, dict[str, str]] = {}
        self.way_refs: dict[int, tuple[int, ...]] = {}
        self.relations: list[tuple[int, list[tuple[str, int, str]], dict[str, str]]] = []

    def way(self, points: list[tuple[float, float]], tags: dict[str, str] | None = None) -> int:
        refs = tuple(self.nodes.setdefault(p, len(self.nodes) + 1) for p in points)
        for key in (refs, refs[::-1]):
            if key in self.ways and tags is None:
                return self.ways[key]
        way_id = len(self.way_tags) + 1
        self.ways.setdefault(refs, way_id)
        self.way_refs[way_id] = refs
        self.way_tags[way_id] = tags or {"type": "line_thin", "subtype": "solid"}
        return way_id

    def text(self) -> str:
        lines = ["<?xml version='1.0' encoding='UTF-8'?>", "<osm version='0.6' generator='scenegrep-tests'>"]
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


def write_lanelet2(av2_map: dict[str, Any], path: Path) -> Path:
    """Write the AV2 map document ``av2_map`` as a Lanelet2 map at ``path`` (see the module docstring)."""
    osm = _Osm()
    for seg in av2_map["lane_segments"].values():
        left, right = _points(seg["left_lane_boundary"]), _points(seg["right_lane_boundary"])
        tags = {"type": "lanelet", "subtype": _KINDS[seg["lane_type"]], "location": "urban", "one_way": "yes"}
        if seg["is_intersection"]:
            tags["turn_direction"] = _turn(left)
        members = [("way", osm.way(left), "left"), ("way", osm.way(right), "right")]
        osm.relations.append((int(seg["id"]), members, tags))
    for k, crossing in enumerate(av2_map["pedestrian_crossings"].values()):
        edge1, edge2 = _points(crossing["edge1"]), _points(crossing["edge2"])
        lanelet_id = CROSSWALK_ID_BASE + k
        members = [("way", osm.way(edge1), "left"), ("way", osm.way(edge2), "right")]
        osm.relations.append((lanelet_id, members, {"type": "lanelet", "subtype": "crosswalk", "one_way": "no"}))
        if k == 0:
            ring = osm.way(edge1 + edge2[::-1], {"type": "crosswalk_polygon", "area": "yes"})
            stop = osm.way(
                [edge1[0], edge2[0]] if edge1[0] != edge2[0] else [edge1[0], edge2[-1]], {"type": "stop_line"}
            )
            members = [
                ("way", stop, "ref_line"),
                ("way", ring, "crosswalk_polygon"),
                ("relation", lanelet_id, "refers"),
            ]
            osm.relations.append(
                (2 * CROSSWALK_ID_BASE, members, {"type": "regulatory_element", "subtype": "crosswalk"})
            )
    path.write_text(osm.text())
    return path
