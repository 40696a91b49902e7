"""A road map as one Arrow table (scenegrep's Parquet map files and map cache).

One row per map element; ``kind`` is lane, road, intersection, crosswalk,
sidewalk, shoulder, curb, stop_line or drivable. Geometries are WKB (polygons; a curb or stop
line is a line string); lanes also carry their centreline and topology columns, sidewalks and crosswalks their
centreline where the map has one (a file written before they were kept has none: their direction
is unknown). The metadata names the
layers the map's format does not publish (``unknown_layers``, layout 2); a layout-1 file, written
before layers were told apart, has every optional layer it holds no element of unknown.
"""

from __future__ import annotations

import json
from collections.abc import Sequence

import numpy as np
import pyarrow as pa
import shapely

from .roadmap import OPTIONAL_LAYERS, Area, Lane, LaneNeighbour, RoadMap

METADATA_KEY = b"scenegrep-map"
LAYOUT_VERSION = 2
READABLE_LAYOUTS = (1, 2)
_AREA_KINDS = ("road", "intersection", "crosswalk", "sidewalk", "shoulder")
_AREA_FIELDS = ("roads", "intersections", "crosswalks", "sidewalks", "shoulders")

SCHEMA = pa.schema(
    [
        ("kind", pa.string()),
        ("id", pa.string()),
        ("geometry", pa.binary()),
        ("centreline", pa.binary()),
        ("road", pa.string()),
        ("is_intersection", pa.bool_()),
        ("successors", pa.list_(pa.string())),
        ("predecessors", pa.list_(pa.string())),
        ("left", pa.string()),
        ("left_same_direction", pa.bool_()),
        ("right", pa.string()),
        ("right_same_direction", pa.bool_()),
        ("lane_kind", pa.string()),
        ("speed_limit", pa.float64()),
        ("lanes", pa.list_(pa.string())),
    ]
)


def _lane_row(lane: Lane) -> dict:
    return {
        "kind": "lane",
        "id": lane.id,
        "geometry": shapely.to_wkb(lane.polygon),
        "centreline": shapely.to_wkb(shapely.linestrings(lane.centreline)),
        "road": lane.road,
        "is_intersection": lane.is_intersection,
        "successors": list(lane.successors),
        "predecessors": list(lane.predecessors),
        "left": lane.left.lane if lane.left else None,
        "left_same_direction": lane.left.same_direction if lane.left else None,
        "right": lane.right.lane if lane.right else None,
        "right_same_direction": lane.right.same_direction if lane.right else None,
        "lane_kind": lane.kind,
        "speed_limit": lane.speed_limit,
    }


def map_to_table(road_map: RoadMap) -> pa.Table:
    """The map as an Arrow table with the :data:`SCHEMA`."""
    rows = [_lane_row(lane) for lane in road_map.lanes]
    for kind, name in zip(_AREA_KINDS, _AREA_FIELDS):
        rows += [
            {
                "kind": kind,
                "id": a.id,
                "geometry": shapely.to_wkb(a.polygon),
                "lanes": list(a.lanes),
                "centreline": None if a.centreline is None else shapely.to_wkb(shapely.linestrings(a.centreline)),
            }
            for a in getattr(road_map, name)
        ]
    rows += [
        {"kind": kind, "id": str(i), "geometry": shapely.to_wkb(shapely.linestrings(line))}
        for kind, lines in (("curb", road_map.curbs), ("stop_line", road_map.stop_lines))
        for i, line in enumerate(lines)
    ]
    if road_map.drivable_area is not None:
        rows.append({"kind": "drivable", "id": "drivable", "geometry": shapely.to_wkb(road_map.drivable_area)})
    table = pa.Table.from_pylist(rows, schema=SCHEMA)
    meta = {
        "layout": LAYOUT_VERSION,
        "name": road_map.name,
        "source": road_map.source,
        "unknown_layers": sorted(road_map.unknown_layers),
    }
    return table.replace_schema_metadata({METADATA_KEY: json.dumps(meta).encode()})


def is_map_table(schema: pa.Schema) -> bool:
    """Whether an Arrow schema carries scenegrep map metadata."""
    return bool(schema.metadata) and METADATA_KEY in schema.metadata


def _neighbour(lane: str | None, same: bool | None) -> LaneNeighbour | None:
    return None if lane is None else LaneNeighbour(lane, bool(same))


def map_from_table(table: pa.Table) -> RoadMap:
    """Rebuild a map from a table written by :func:`map_to_table`; ValueError if it is not one."""
    if not is_map_table(table.schema):
        raise ValueError("not a scenegrep map table (no scenegrep-map metadata)")
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    if meta.get("layout") not in READABLE_LAYOUTS:
        raise ValueError(f"unsupported map layout {meta.get('layout')!r}")
    rows = table.to_pylist()
    geometry = shapely.from_wkb(np.array([r["geometry"] for r in rows], dtype=object))
    lanes, areas, lines, drivable = [], {k: [] for k in _AREA_KINDS}, {"curb": [], "stop_line": []}, None
    for row, geom in zip(rows, geometry):
        kind = row["kind"]
        if kind == "lane":
            lanes.append(
                Lane(
                    row["id"],
                    geom,
                    _coordinates(row["centreline"]),
                    row["road"],
                    bool(row["is_intersection"]),
                    tuple(row["successors"] or ()),
                    tuple(row["predecessors"] or ()),
                    _neighbour(row["left"], row["left_same_direction"]),
                    _neighbour(row["right"], row["right_same_direction"]),
                    row["lane_kind"],
                    row["speed_limit"],
                )
            )
        elif kind in areas:
            centre = None if row["centreline"] is None else _coordinates(row["centreline"])
            areas[kind].append(Area(row["id"], geom, tuple(row["lanes"] or ()), centre))
        elif kind in lines:
            lines[kind].append(shapely.get_coordinates(geom))
        elif kind == "drivable":
            drivable = geom
    road, intersection, crosswalk, sidewalk, shoulder = (tuple(areas[k]) for k in _AREA_KINDS)
    curbs = lines["curb"]
    held = {"crossing": crosswalk, "sidewalk": sidewalk, "curb": curbs, "shoulder": shoulder}
    return RoadMap(
        meta["name"],
        tuple(lanes),
        road,
        intersection,
        crosswalk,
        sidewalk,
        tuple(curbs),
        drivable,
        meta.get("source"),
        shoulder,
        _unknown_layers(meta, held),
        tuple(lines["stop_line"]),
    )


def _coordinates(wkb: bytes) -> np.ndarray:
    """The k x 2 vertices of a line string stored as WKB."""
    return shapely.get_coordinates(shapely.from_wkb(wkb))


def _unknown_layers(meta: dict, held: dict[str, Sequence]) -> frozenset[str]:
    """The unknown layers the metadata names; for layout 1, the optional layers without elements."""
    if meta["layout"] == 1:
        return frozenset(layer for layer in OPTIONAL_LAYERS if not held[layer])
    names = meta.get("unknown_layers")
    if not isinstance(names, list) or not set(names) <= set(OPTIONAL_LAYERS):
        raise ValueError(f"bad unknown_layers {names!r} in the map metadata")
    return frozenset(names)
