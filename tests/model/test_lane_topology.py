"""Topology derived from geometry: successors from touching ends, neighbours, roads, intersections."""

from scenegrep.model.lane_topology import (
    derive_intersections,
    derive_roads,
    link_by_endpoints,
    neighbours_from_geometry,
)
from tests.model.maps import synthetic_lanes


def by_id(lanes):
    return {lane.id: lane for lane in lanes}


def test_link_by_endpoints():
    lanes = by_id(link_by_endpoints(synthetic_lanes()))
    assert lanes["n1"].successors == ("n1b",) and lanes["n1b"].predecessors == ("n1",)
    assert lanes["n2"].successors == () and lanes["s1"].predecessors == ()


def test_neighbours_from_geometry_with_directions():
    lanes = by_id(neighbours_from_geometry(synthetic_lanes()))
    assert (lanes["n1"].right.lane, lanes["n1"].right.same_direction) == ("n2", True)
    assert (lanes["n1"].left.lane, lanes["n1"].left.same_direction) == ("s1", False)
    assert (lanes["s1"].left.lane, lanes["s1"].left.same_direction) == ("n1", False)
    assert lanes["n2"].right is None and lanes["n1b"].left is None


def test_roads_and_intersections():
    lanes = neighbours_from_geometry(synthetic_lanes())
    roads = derive_roads(lanes)
    assert sorted(sorted(r.lanes) for r in roads) == [["n1", "n2", "s1"], ["n1b"]]
    (intersection,) = derive_intersections(lanes)
    assert intersection.lanes == ("x1",) and intersection.polygon.area == 10.5 * 3.5
