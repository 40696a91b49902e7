"""The inverted walk tries a centreline segment's heading only where the new point may lie in its
lane's (or shoulder's) holding region (:func:`scenegrep.scene.follow_inverse._holders`): every
point whose road direction Scenic reads off a centreline lies in that centreline's region. Checked
on Town01 at random points near the roads and at points just inside and outside the lanes' and
intersection areas' boundaries and Scenic's 5 cm band (where the rules change), against
:meth:`~scenegrep.scene.geometry.MapGeometry.scenic_headings` itself."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from scenegrep.scene.follow_inverse import inverse
from tests.scene.test_follow import FIELD
from tests.scene.test_follow_start import town01


def boundary_points(polygons, rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` points on the rings of random polygons, each moved by up to 8 cm across them."""
    rings = shapely.get_rings(shapely.get_parts(np.asarray(polygons, dtype=object)))
    pick = rings[rng.integers(len(rings), size=n)]
    points = shapely.line_interpolate_point(pick, rng.uniform(0, 1, n), normalized=True)
    return shapely.get_coordinates(points) + rng.uniform(-0.08, 0.08, (n, 2))


@pytest.mark.real_data
def test_every_point_lies_in_the_holding_region_of_the_centreline_giving_its_heading():
    found = town01()
    if found is None:
        pytest.skip("../shared/maps/Town01.xodr is absent")
    geometry, roads = found
    road_map = geometry.map
    inv = inverse(geometry)
    rng = np.random.default_rng(7)
    x0, y0, x1, y1 = roads.bounds
    spread = np.stack([rng.uniform(x0, x1, 20000), rng.uniform(y0, y1, 20000)], axis=1)
    spread = spread[shapely.dwithin(shapely.points(spread), roads, 1.0)]
    areas = [a.polygon for a in road_map.intersections]
    bands = shapely.buffer(shapely.union_all(road_map.lane_polygons), 0.05)
    points = np.concatenate(
        [
            spread,
            boundary_points(road_map.lane_polygons, rng, 6000),
            boundary_points(areas, rng, 3000),
            boundary_points([bands], rng, 2000),
            boundary_points([a.polygon for a in road_map.shoulders], rng, 2000),
        ]
    )
    heading = geometry.scenic_headings(FIELD, points[:, 0], points[:, 1], None)
    order = np.argsort(inv.heading, kind="stable")
    first = np.searchsorted(inv.heading[order], heading, side="left")
    last = np.searchsorted(inv.heading[order], heading, side="right")
    taken = np.flatnonzero(last > first)
    assert len(taken) > 0.9 * len(points) - np.count_nonzero(heading == 0)
    point = np.repeat(taken, (last - first)[taken])
    offset = np.arange(len(point)) - np.repeat(
        np.cumsum((last - first)[taken]) - (last - first)[taken], (last - first)[taken]
    )
    segment = order[first[point] + offset]
    held = shapely.intersects(inv.holds[inv.owner[segment]], shapely.points(points[point]))
    inside = np.zeros(len(points), dtype=bool)
    inside[point[held]] = True
    assert inside[taken].all(), points[taken[~inside[taken]]][:5]
