"""A road map written as Lanelet2 (:func:`scenegrep.writers.lanelet2.write_road_map_lanelet2`) reads
back (:mod:`scenegrep.readers.lanelet2`) with the map's topology, layers and lane answers: on the
Town06 crop examples/map.parquet (lanes, shoulders, curbs) and on hand-made straight roads in any
direction (neighbours either way round, successors, a crossing and a sidewalk). Lane ``i`` of the
map is lanelet ``i + 1``."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep import readers
from scenegrep.model import Area, Lane, LaneNeighbour, RoadMap
from scenegrep.model.lane_shapes import lane_polygon
from scenegrep.readers.lanelet2 import convert
from scenegrep.writers.lanelet2 import write_road_map_lanelet2
from tests.conftest import REPO

EXAMPLES = REPO / "examples"


def lanelet_ids(road_map: RoadMap) -> dict[str, str]:
    """Each lane id of ``road_map`` -> the id of the lanelet written for it."""
    return {lane.id: str(i + 1) for i, lane in enumerate(road_map.lanes)}


def topology(road_map: RoadMap, ids: dict[str, str] | None = None) -> dict[str, tuple]:
    """Per lane (renamed by ``ids``): successors, predecessors, left and right neighbours (links
    to lanes the map does not hold left out), intersection flag and kind."""
    ids = ids or {lane.id: lane.id for lane in road_map.lanes}

    def side(n: LaneNeighbour | None):
        return (ids[n.lane], n.same_direction) if n is not None and n.lane in ids else None

    return {
        ids[lane.id]: (
            sorted(ids[s] for s in lane.successors if s in ids),
            sorted(ids[p] for p in lane.predecessors if p in ids),
            side(lane.left),
            side(lane.right),
            lane.is_intersection,
            lane.kind,
        )
        for lane in road_map.lanes
    }


@pytest.fixture(scope="module")
def town(tmp_path_factory):
    """examples/map.parquet and what its Lanelet2 map reads back as."""
    road_map = readers.read_map(EXAMPLES / "map.parquet")
    path = write_road_map_lanelet2(road_map, tmp_path_factory.mktemp("lanelet2") / "town.osm")
    return road_map, convert(path)


def test_the_town_crop_keeps_its_topology(town):
    road_map, back = town
    assert topology(back) == topology(road_map, lanelet_ids(road_map))
    assert len(back.intersections) == len(road_map.intersections) == 3


def test_every_point_well_inside_a_lane_is_in_its_lanelet(town):
    """Points 0.3 m or more inside a lane's polygon lie in its lanelet, whose direction there is the
    lane's (the lanelet's centerline is the lane's centreline)."""
    road_map, back = town
    ids = lanelet_ids(road_map)
    x0, y0, x1, y1 = road_map.bounds()
    rng = np.random.default_rng(0)
    x, y = rng.uniform(x0, x1, 20_000), rng.uniform(y0, y1, 20_000)
    checked = np.zeros(len(x), dtype=bool)
    for lane in road_map.lanes:
        inside = shapely.contains_xy(lane.polygon.buffer(-0.3), x, y)
        lanelet = back.lanes[back.lane_index[ids[lane.id]]]
        assert shapely.contains_xy(lanelet.polygon, x[inside], y[inside]).all(), lane.id
        checked |= inside
    assert checked.sum() > 4_000
    x, y = x[checked], y[checked]
    assert np.array_equal(back.lane_direction_at(x, y), road_map.lane_direction_at(x, y))


def test_the_sample_trace_is_in_the_same_lanes(town):
    road_map, back = town
    trace = readers.read_trace(EXAMPLES / "sample" / "fig1_lane_change-000.parquet")
    s = trace.states
    ids = lanelet_ids(road_map)
    expected = [ids[road_map.lanes[i].id] for i in road_map.lane_at(s.x, s.y, s.heading)]
    assert [back.lanes[i].id for i in back.lane_at(s.x, s.y, s.heading)] == expected


def test_shoulders_and_curbs_come_back_and_no_layer_is_unknown(town):
    road_map, back = town
    assert len(back.shoulders) == len(road_map.shoulders) == 9
    for mine, theirs in zip(road_map.shoulders, back.shoulders):
        overlap = mine.polygon.intersection(theirs.polygon).area / mine.polygon.union(theirs.polygon).area
        assert overlap > 0.99, mine.id
    assert len(back.curbs) == len(road_map.curbs) and all(
        np.array_equal(a, b) for a, b in zip(back.curbs, road_map.curbs)
    )
    assert back.unknown_layers == frozenset() and not back.crosswalks and not back.sidewalks


WIDTH = 3.5


def straight_roads(angle: float, lanes: int, oncoming: bool, origin: tuple[float, float]) -> RoadMap:
    """``lanes`` parallel lanes of two 30 m segments each (``a<k>`` then ``b<k>``), rotated by
    ``angle`` about ``origin``; with ``oncoming`` the last lane runs the other way. A crossing
    over the ``a`` segments and a sidewalk beside them, both with centrelines."""
    direction = np.array([math.cos(angle), math.sin(angle)])
    left = np.array([-direction[1], direction[0]])
    at = np.asarray(origin)

    def line(s0: float, s1: float, offset: float) -> np.ndarray:
        return np.array([at + s * direction + offset * left for s in np.linspace(s0, s1, 7)])

    def heads_back(k: int) -> bool:
        return oncoming and k == lanes - 1

    def neighbour(k: int, j: int, segment: str) -> LaneNeighbour | None:
        return LaneNeighbour(f"{segment}{j}", heads_back(k) == heads_back(j)) if 0 <= j < lanes else None

    made = []
    for k in range(lanes):
        back = heads_back(k)
        for segment, (s0, s1) in (("a", (0.0, 30.0)), ("b", (30.0, 60.0))):
            centre = line(s1, s0, k * WIDTH) if back else line(s0, s1, k * WIDTH)
            after, before = ("a", "b") if back else ("b", "a")
            ahead = (f"{after}{k}",) if segment != after else ()
            behind = (f"{before}{k}",) if segment != before else ()
            inner, outer = neighbour(k, k - 1, segment), neighbour(k, k + 1, segment)
            made.append(
                Lane(
                    f"{segment}{k}",
                    lane_polygon(centre, WIDTH / 2, WIDTH / 2),
                    centre,
                    successors=ahead,
                    predecessors=behind,
                    left=inner if back else outer,
                    right=outer if back else inner,
                )
            )
    crossing_line = np.array([at + 15 * direction + t * left for t in (-WIDTH / 2, (lanes - 0.5) * WIDTH)])
    sidewalk_line = line(0.0, 30.0, -WIDTH / 2 - 1.5)
    return RoadMap(
        "straight",
        tuple(made),
        crosswalks=(Area("x", lane_polygon(crossing_line, 2.0, 2.0), centreline=crossing_line),),
        sidewalks=(Area("w", lane_polygon(sidewalk_line, 1.0, 1.0), centreline=sidewalk_line),),
    )


@settings(max_examples=25, deadline=None)
@given(
    angle=st.floats(-math.pi, math.pi),
    lanes=st.integers(1, 4),
    oncoming=st.booleans(),
    origin=st.tuples(st.floats(-5e3, 5e3), st.floats(-5e3, 5e3)),
)
def test_straight_roads_in_any_direction_come_back(tmp_path_factory, angle, lanes, oncoming, origin):
    road_map = straight_roads(angle, lanes, oncoming and lanes > 1, origin)
    back = convert(write_road_map_lanelet2(road_map, tmp_path_factory.mktemp("straight") / "map.osm"))
    assert topology(back) == topology(road_map, lanelet_ids(road_map))
    for mine, theirs in [*zip(road_map.lanes, back.lanes), *zip(road_map.crosswalks, back.crosswalks)]:
        assert mine.polygon.symmetric_difference(theirs.polygon).area < 1e-6 * mine.polygon.area + 1e-6
    assert [len(back.crosswalks), len(back.sidewalks)] == [1, 1]
    assert back.sidewalks[0].polygon.symmetric_difference(road_map.sidewalks[0].polygon).area < 1e-6


def test_maps_it_cannot_write_truthfully_are_refused(tmp_path):
    road_map = straight_roads(0.0, 2, False, (0.0, 0.0))
    with pytest.raises(ValueError, match="does not know its sidewalk layers"):
        write_road_map_lanelet2(replace(road_map, unknown_layers=frozenset({"sidewalk"})), tmp_path / "a.osm")
    crossing = replace(road_map.crosswalks[0], centreline=None)
    with pytest.raises(ValueError, match="crosswalks area x has no centreline"):
        write_road_map_lanelet2(replace(road_map, crosswalks=(crossing,)), tmp_path / "b.osm")
    assert not (tmp_path / "a.osm").exists() and not (tmp_path / "b.osm").exists()
