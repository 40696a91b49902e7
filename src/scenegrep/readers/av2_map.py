"""Argoverse 2 vector maps (``log_map_archive_*.json``): lane segments, drivable areas,
pedestrian crossings, in the city frame.

Lane boundaries run in the direction of travel; a lane's centreline is the mean of
its two boundaries resampled to the same number of points (the forecasting
maps' own ``centerline`` is used when present). AV2 names no intersections or
roads: intersection areas are the connected unions of the lanes flagged
``is_intersection``, and roads the laterally linked groups of the other lanes.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import orjson
import shapely

from ..errors import UserError, at
from ..model import Area, Lane, LaneNeighbour, RoadMap
from ..model.lane_shapes import centreline_between, polygon_between
from ..model.lane_topology import derive_intersections, derive_roads
from .common import field, read_bytes, reading

FORMAT = "av2-map"
_LANE_KINDS = {"VEHICLE": "vehicle", "BIKE": "bike", "BUS": "bus"}
UNKNOWN_LAYERS = frozenset({"sidewalk", "curb", "shoulder"})
"""Layers the AV2 map format does not publish (its drivable area includes the shoulders)."""


def find_map(directory: Path) -> Path | None:
    """The ``log_map_archive_*.json`` in a log directory or its ``map/`` folder, if any."""
    for folder in (directory / "map", directory):
        found = sorted(folder.glob("log_map_archive_*.json"))
        if found:
            return found[0]
    return None


def _polyline(points: list[dict[str, float]], path: Path, where: str) -> np.ndarray:
    try:
        return np.array([[p["x"], p["y"]] for p in points], dtype=np.float64)
    except (KeyError, TypeError):
        raise UserError(f"malformed polyline in {where}: expected a list of {{x, y, z}} points", at(path)) from None


def _lane(seg: dict[str, Any], path: Path, directions: dict[str, np.ndarray]) -> Lane:
    lane_id = str(field(seg, "id", path, "a lane segment"))
    where = f"lane segment {lane_id}"
    left = _polyline(field(seg, "left_lane_boundary", path, where), path, where)
    right = _polyline(field(seg, "right_lane_boundary", path, where), path, where)
    centre = _polyline(seg["centerline"], path, where) if "centerline" in seg else centreline_between(left, right)
    directions[lane_id] = centre[-1] - centre[0]
    polygon = polygon_between(left, right)
    return Lane(
        lane_id,
        polygon,
        centre,
        is_intersection=bool(field(seg, "is_intersection", path, where)),
        successors=tuple(str(s) for s in seg.get("successors") or ()),
        predecessors=tuple(str(s) for s in seg.get("predecessors") or ()),
        kind=_LANE_KINDS.get(str(seg.get("lane_type")), "vehicle"),
    )


def _with_neighbours(
    lanes: list[Lane], segments: list[dict[str, Any]], directions: dict[str, np.ndarray]
) -> list[Lane]:
    """Lanes with left/right neighbours; same direction when the centrelines point the same way."""
    out = []
    for lane, seg in zip(lanes, segments):
        sides = {}
        for side in ("left", "right"):
            other = seg.get(f"{side}_neighbor_id")
            if other is not None and str(other) in directions:
                same = float(np.dot(directions[lane.id], directions[str(other)])) > 0
                sides[side] = LaneNeighbour(str(other), same)
        out.append(replace(lane, **sides))
    return out


def read_map(path: str | Path) -> RoadMap:
    """Read an Argoverse 2 map JSON file."""
    path = Path(path)
    with reading(path, "Argoverse 2 map (JSON)", orjson.JSONDecodeError):
        doc = orjson.loads(read_bytes(path))
    if not isinstance(doc, dict):
        raise UserError("expected a JSON object with lane_segments", at(path))
    segments = list(field(doc, "lane_segments", path, "the map").values())
    directions: dict[str, np.ndarray] = {}
    lanes = _with_neighbours([_lane(s, path, directions) for s in segments], segments, directions)
    crossings = tuple(
        Area(
            str(c.get("id", k)),
            shapely.Polygon(
                np.vstack(
                    [
                        _polyline(field(c, "edge1", path, "a pedestrian crossing"), path, "a pedestrian crossing"),
                        _polyline(field(c, "edge2", path, "a pedestrian crossing"), path, "a pedestrian crossing")[
                            ::-1
                        ],
                    ]
                )
            ),
        )
        for k, c in enumerate(doc.get("pedestrian_crossings", {}).values())
    )
    areas = [
        shapely.make_valid(
            shapely.Polygon(_polyline(field(a, "area_boundary", path, "a drivable area"), path, "a drivable area"))
        )
        for a in doc.get("drivable_areas", {}).values()
    ]
    drivable = shapely.union_all(areas) if areas else None
    return RoadMap(
        path.stem,
        tuple(lanes),
        derive_roads(lanes),
        derive_intersections(lanes),
        crossings,
        drivable_area=drivable,
        source=str(path),
        unknown_layers=UNKNOWN_LAYERS,
    )
