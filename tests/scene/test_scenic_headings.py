"""Scenic's road direction at points (:meth:`~scenegrep.scene.geometry.MapGeometry.scenic_headings`)
and its containment lookups, on Town01 and Town06, against plain references: the R-tree's own predicate for
the prepared-polygon lookup (:func:`scenegrep.model.roadmap.tree_containing`), and a point-by-point
reading of Scenic's rules (the first intersection area holding the point and there the first of
its lanes holding it, else the nearest; else the first lane; off the lanes the first shoulder,
then within 5 cm an intersection area, the nearest lane, a shoulder; else 0) at random points
near the roads, just inside and outside the lanes', intersection areas', shoulders' and 5 cm
bands' boundaries, and on their vertices."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from scenegrep.readers.opendrive import read_map
from scenegrep.model.roadmap import tree_containing
from scenegrep.scene.geometry import ELEMENT_REACH_M, geometry_of
from tests.scene.test_follow import FIELD
from tests.scene.test_follow_holders import boundary_points


@pytest.fixture(scope="module", params=["Town01", "Town06"])
def town(request, maps_dir):
    geometry = geometry_of(read_map(maps_dir / f"{request.param}.xodr"))
    road_map = geometry.map
    areas = [a.polygon for a in road_map.intersections]
    shoulders = [a.polygon for a in road_map.shoulders]
    roads = shapely.union_all(list(road_map.lane_polygons) + areas)
    rng = np.random.default_rng(3)
    x0, y0, x1, y1 = roads.bounds
    spread = np.stack([rng.uniform(x0, x1, 4000), rng.uniform(y0, y1, 4000)], axis=1)
    spread = spread[shapely.dwithin(shapely.points(spread), roads, 1.0)][:300]
    band = shapely.buffer(shapely.union_all(road_map.lane_polygons), ELEMENT_REACH_M)
    vertices = shapely.get_coordinates(np.array(areas + shoulders, dtype=object))
    points = np.concatenate(
        [
            spread,
            boundary_points(road_map.lane_polygons, rng, 300),
            boundary_points(areas, rng, 200),
            boundary_points(shoulders, rng, 150),
            boundary_points([band], rng, 300),
            vertices[rng.integers(len(vertices), size=100)],
        ]
    )
    return geometry, points


@pytest.mark.real_data
def test_prepared_containment_finds_what_the_tree_predicate_finds(town):
    geometry, points = town
    shapes = shapely.points(points)
    trees = [geometry.map._lane_tree, geometry._intersection_areas[0], geometry._shoulders[0]]
    for tree in trees:
        found = sorted(zip(*(a.tolist() for a in tree_containing(tree, shapes))))
        expected = sorted(zip(*(a.tolist() for a in tree.query(shapes, predicate="intersects"))))
        assert found == expected
        assert found


def reference_heading(geometry, x: float, y: float) -> float:
    """Scenic's road direction at (x, y), read rule by rule with one point at a time."""
    road_map = geometry.map
    point = shapely.Point(x, y)
    lanes, lines = road_map.lane_polygons, road_map.centreline_polylines
    _, shoulder_lines = geometry._shoulders
    shoulders = np.array([a.polygon for a in road_map.shoulders], dtype=object)
    areas = [a.polygon for a in road_map.intersections]

    def along(polylines, k: int) -> float:
        return float(polylines.direction_at(np.array([k]), np.array([x]), np.array([y]))[0])

    def area_lane(k: int) -> int:
        mine = [road_map.lane_index[lane] for lane in road_map.intersections[k].lanes if lane in road_map.lane_index]
        holding = [m for m in mine if lanes[m].intersects(point)]
        return holding[0] if holding else mine[int(np.argmin([lanes[m].distance(point) for m in mine]))]

    inside = [k for k, area in enumerate(areas) if area.intersects(point)]
    if inside:
        return along(lines, area_lane(inside[0]))
    holding = np.flatnonzero(shapely.intersects(lanes, point))
    if len(holding):
        return along(lines, holding[0])
    holding = np.flatnonzero(shapely.intersects(shoulders, point))
    if len(holding):
        return along(shoulder_lines, holding[0])
    near = [k for k, area in enumerate(areas) if shapely.dwithin(area, point, ELEMENT_REACH_M)]
    if near:
        return along(lines, area_lane(near[0]))
    distance = shapely.distance(lanes, point)
    if distance.min() <= ELEMENT_REACH_M:
        return along(lines, int(np.argmin(distance)))
    holding = np.flatnonzero(shapely.dwithin(shoulders, point, ELEMENT_REACH_M))
    return along(shoulder_lines, holding[0]) if len(holding) else 0.0


@pytest.mark.real_data
def test_scenic_headings_follow_scenics_rules_point_by_point(town):
    geometry, points = town
    found = geometry.scenic_headings(FIELD, points[:, 0], points[:, 1], None)
    expected = np.array([reference_heading(geometry, x, y) for x, y in points.tolist()])
    assert np.array_equal(found, expected)
    assert np.count_nonzero(expected == 0) < len(points) // 2 < np.count_nonzero(expected)
