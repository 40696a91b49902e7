"""Derive lane topology a map does not state: successors from touching end points,
left/right neighbours (with their direction of travel) from geometry.

Some datasets (nuScenes through ScenarioNet, for one) give lanes as bare centrelines
and polygons. These functions fill in the links from geometry; links a map does
state are never overwritten.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely
from shapely import STRtree

from .geometry import heading_difference
from .lane_shapes import line_strings
from .roadmap import Area, Lane, LaneNeighbour, RoadMap

ENDPOINT_TOLERANCE_M = 0.5
"""Two lanes connect when one's end point lies this close (m) to the other's start point."""

PARALLEL_TOLERANCE_RAD = np.radians(30.0)
"""Lanes whose directions differ by less than this (or by more than pi minus this) are parallel."""


def _lane_width(lane: Lane) -> float:
    length = float(shapely.length(shapely.linestrings(lane.centreline)))
    return float(lane.polygon.area / length) if length > 0 else 0.0


def link_by_endpoints(lanes: list[Lane], tolerance: float = ENDPOINT_TOLERANCE_M) -> list[Lane]:
    """Lanes with successors/predecessors added where an end point meets a start point."""
    starts = shapely.points(np.array([lane.centreline[0] for lane in lanes]))
    ends = shapely.points(np.array([lane.centreline[-1] for lane in lanes]))
    src, dst = STRtree(starts).query(ends, predicate="dwithin", distance=tolerance)
    keep = src != dst
    successors: dict[int, list[str]] = {}
    predecessors: dict[int, list[str]] = {}
    for a, b in zip(src[keep].tolist(), dst[keep].tolist()):
        successors.setdefault(a, []).append(lanes[b].id)
        predecessors.setdefault(b, []).append(lanes[a].id)
    return [
        replace(
            lane,
            successors=lane.successors or tuple(successors.get(i, ())),
            predecessors=lane.predecessors or tuple(predecessors.get(i, ())),
        )
        for i, lane in enumerate(lanes)
    ]


def neighbours_from_geometry(lanes: list[Lane]) -> list[Lane]:
    """Lanes with left/right neighbours added: the parallel lane (same or opposite direction)
    containing the point one lane width to the side of the centreline's midpoint."""
    road_map = RoadMap("probe", tuple(lanes))
    lines = line_strings([lane.centreline for lane in lanes])
    mids = shapely.line_interpolate_point(lines, 0.5, normalized=True)
    mx, my = shapely.get_x(mids), shapely.get_y(mids)
    headings = road_map.lane_direction_at(mx, my, np.arange(len(lanes)))
    widths = np.array([_lane_width(lane) for lane in lanes])
    found = []
    for sign in (1.0, -1.0):
        px = mx - sign * np.cos(headings) * widths
        py = my - sign * np.sin(headings) * widths
        point_idx, lane_idx = road_map.lanes_containing(px, py)
        other = point_idx != lane_idx
        point_idx, lane_idx = point_idx[other], lane_idx[other]
        theirs = road_map.lane_direction_at(px[point_idx], py[point_idx], lane_idx)
        delta = np.abs(heading_difference(theirs, headings[point_idx]))
        parallel = (delta < PARALLEL_TOLERANCE_RAD) | (delta > np.pi - PARALLEL_TOLERANCE_RAD)
        side: dict[int, LaneNeighbour] = {}
        for p, q, same in zip(
            point_idx[parallel].tolist(),
            lane_idx[parallel].tolist(),
            (delta[parallel] < PARALLEL_TOLERANCE_RAD).tolist(),
        ):
            side.setdefault(p, LaneNeighbour(lanes[q].id, same))
        found.append(side)
    left, right = found
    return [
        replace(lane, left=lane.left or left.get(i), right=lane.right or right.get(i)) for i, lane in enumerate(lanes)
    ]


def _components(n: int, links: list[tuple[int, int]]) -> list[list[int]]:
    """Connected components of a graph on 0..n-1 (union-find)."""
    parent = list(range(n))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in links:
        parent[find(a)] = find(b)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return list(groups.values())


def derive_intersections(lanes: list[Lane], gap: float = 0.5) -> tuple[Area, ...]:
    """Intersection areas: connected unions of the lanes flagged ``is_intersection``
    (polygons closer than ``gap`` metres join)."""
    inside = [lane for lane in lanes if lane.is_intersection]
    if not inside:
        return ()
    merged = shapely.union_all([shapely.buffer(lane.polygon, gap / 2) for lane in inside])
    parts = list(getattr(merged, "geoms", [merged]))
    tree = STRtree(np.array([lane.polygon for lane in inside], dtype=object))
    areas = []
    for k, part in enumerate(parts):
        members = tree.query(part, predicate="intersects")
        polygon = shapely.union_all([inside[i].polygon for i in members])
        areas.append(Area(f"intersection{k}", polygon, tuple(inside[i].id for i in sorted(members))))
    return tuple(areas)


def derive_roads(lanes: list[Lane]) -> tuple[Area, ...]:
    """Road areas: groups of non-intersection lanes linked as left/right neighbours."""
    outside = [lane for lane in lanes if not lane.is_intersection]
    index = {lane.id: i for i, lane in enumerate(outside)}
    links = [
        (i, index[n.lane])
        for i, lane in enumerate(outside)
        for n in (lane.left, lane.right)
        if n is not None and n.lane in index
    ]
    return tuple(
        Area(f"road{k}", shapely.union_all([outside[i].polygon for i in group]), tuple(outside[i].id for i in group))
        for k, group in enumerate(_components(len(outside), links))
    )


CROSSING_END_MARGIN_M = 1.0
CROSSING_MIN_ANGLE_RAD = np.radians(20.0)
CROSSING_MAX_HEIGHT_GAP_M = 2.0


def _direction_at(line: shapely.LineString, point: shapely.Point) -> np.ndarray:
    s = shapely.line_locate_point(line, point)
    a = shapely.line_interpolate_point(line, max(s - 0.5, 0.0))
    b = shapely.line_interpolate_point(line, min(s + 0.5, line.length))
    v = np.array([b.x - a.x, b.y - a.y])
    return v / (np.linalg.norm(v) or 1.0)


def _height_at(centreline: np.ndarray, line: shapely.LineString, point: shapely.Point) -> float:
    if centreline.shape[1] < 3:
        return 0.0
    arc = np.r_[0.0, np.cumsum(np.hypot(*np.diff(centreline[:, :2], axis=0).T))]
    return float(np.interp(shapely.line_locate_point(line, point), arc, centreline[:, 2]))


def _far_from_ends(point: np.ndarray, *centrelines: np.ndarray) -> bool:
    return all(
        min(np.hypot(*(c[0, :2] - point)), np.hypot(*(c[-1, :2] - point))) > CROSSING_END_MARGIN_M for c in centrelines
    )


def crossing_lanes(centrelines: list[np.ndarray]) -> np.ndarray:
    """Which lanes cross another lane, as lanes do inside an intersection (boolean per lane).

    Two centrelines (k x 2, or k x 3 with heights) cross when they intersect at a point more
    than :data:`CROSSING_END_MARGIN_M` from every end of both (lanes that merge or split at
    their ends do not count), at an angle above :data:`CROSSING_MIN_ANGLE_RAD`, and (with
    heights) less than :data:`CROSSING_MAX_HEIGHT_GAP_M` apart vertically (an overpass is
    not an intersection).
    """
    lines = line_strings(centrelines)
    crossing = np.zeros(len(centrelines), dtype=bool)
    first, second = STRtree(lines).query(lines, predicate="crosses")
    for i, j in zip(first.tolist(), second.tolist()):
        if i >= j or (crossing[i] and crossing[j]):
            continue
        for xy in shapely.get_coordinates(shapely.intersection(lines[i], lines[j])):
            point = shapely.Point(xy)
            cos = abs(float(np.dot(_direction_at(lines[i], point), _direction_at(lines[j], point))))
            level = abs(_height_at(centrelines[i], lines[i], point) - _height_at(centrelines[j], lines[j], point))
            if (
                _far_from_ends(xy, centrelines[i], centrelines[j])
                and np.arccos(min(cos, 1.0)) > CROSSING_MIN_ANGLE_RAD
                and level < CROSSING_MAX_HEIGHT_GAP_M
            ):
                crossing[i] = crossing[j] = True
                break
    return crossing
