"""RoadMap point queries against brute-force shapely checks, directions, cropping, round trip."""

import json
import math
from dataclasses import replace

import numpy as np
import pyarrow as pa
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.model.map_arrow import METADATA_KEY, map_from_table, map_to_table
from tests.model.maps import synthetic_map

ROAD_MAP = synthetic_map()
coords = st.lists(st.tuples(st.floats(-10, 12), st.floats(-10, 210)), max_size=30)


@given(coords)
def test_lanes_containing_matches_brute_force(points):
    xy = np.array(points, dtype=float).reshape(-1, 2)
    got = set(zip(*[a.tolist() for a in ROAD_MAP.lanes_containing(xy[:, 0], xy[:, 1])]))
    expected = {
        (i, j)
        for i, (x, y) in enumerate(points)
        for j, lane in enumerate(ROAD_MAP.lanes)
        if lane.polygon.intersects(shapely.Point(x, y))
    }
    assert got == expected


@given(coords)
def test_region_membership_matches_brute_force(points):
    xy = np.array(points, dtype=float).reshape(-1, 2)
    for region, areas in (
        ("crossing", ROAD_MAP.crosswalks),
        ("road", ROAD_MAP.roads),
        ("intersection", ROAD_MAP.intersections),
    ):
        expected = [any(a.polygon.intersects(shapely.Point(x, y)) for a in areas) for x, y in points]
        assert ROAD_MAP.contains(region, xy[:, 0], xy[:, 1]).tolist() == expected


def test_lane_direction_follows_travel():
    x = np.array([1.0, 5.0, -2.0, 1.0])
    y = np.array([20.0, 20.0, 20.0, 150.0])
    lanes = ROAD_MAP.lane_at(x, y)
    assert [ROAD_MAP.lanes[i].id for i in lanes] == ["n1", "n2", "s1", "n1b"]
    assert np.allclose(ROAD_MAP.lane_direction_at(x, y), [0, 0, math.pi, 0])
    assert np.isnan(ROAD_MAP.lane_direction_at(np.array([50.0]), np.array([50.0]))[0])


def test_overlapping_lanes_resolved_by_heading_or_distance():
    x, y = np.array([1.0]), np.array([51.0])
    assert ROAD_MAP.lanes[ROAD_MAP.lane_at(x, y, heading=np.array([0.0]))[0]].id == "n1"
    assert ROAD_MAP.lanes[ROAD_MAP.lane_at(x, y, heading=np.array([-math.pi / 2]))[0]].id == "x1"
    assert ROAD_MAP.lanes[ROAD_MAP.lane_at(x, np.array([51.7]))[0]].id == "x1"
    assert sorted(np.round(ROAD_MAP.nominal_directions_at(1.0, 51.0), 6)) == sorted([0.0, round(-math.pi / 2, 6)])


def test_in_intersection_and_unknown_region():
    assert ROAD_MAP.in_intersection(np.array([1.0, 1.0]), np.array([52.0, 20.0])).tolist() == [True, False]
    with pytest.raises(KeyError):
        ROAD_MAP.contains("parking", np.array([0.0]), np.array([0.0]))


def test_crop_keeps_only_nearby_elements():
    cropped = ROAD_MAP.crop(1.75, 150.0, 10.0)
    assert [lane.id for lane in cropped.lanes] == ["n1b"]
    assert cropped.lanes[0].successors == () and not cropped.crosswalks
    assert {lane.id for lane in ROAD_MAP.crop(0.0, 52.0, 1.0).lanes} == {"n1", "s1", "x1"}


def test_map_table_round_trip():
    assert map_from_table(map_to_table(ROAD_MAP)).equals(ROAD_MAP)
    assert not map_from_table(map_to_table(ROAD_MAP.crop(0, 0, 5))).equals(ROAD_MAP)


def test_map_table_round_trips_the_unknown_layers():
    assert ROAD_MAP.unknown_layers == {"sidewalk", "shoulder"}
    assert map_from_table(map_to_table(ROAD_MAP)).unknown_layers == ROAD_MAP.unknown_layers
    published = replace(ROAD_MAP, unknown_layers=frozenset())
    assert map_from_table(map_to_table(published)).equals(published)
    assert not map_from_table(map_to_table(published)).equals(ROAD_MAP)


def test_map_table_round_trips_the_crosswalk_centrelines():
    again = map_from_table(map_to_table(ROAD_MAP))
    assert np.array_equal(again.crosswalks[0].centreline, [[-3.5, 61.5], [7, 61.5]])
    assert again.orients("crossing") and not again.orients("sidewalk")  # sidewalks: an unknown layer
    without = replace(ROAD_MAP, crosswalks=(replace(ROAD_MAP.crosswalks[0], centreline=None),))
    assert not without.equals(ROAD_MAP)
    assert map_from_table(map_to_table(without)).equals(without) and not without.orients("crossing")


def test_an_older_map_table_has_no_crosswalk_centrelines_so_their_direction_is_unknown():
    """Files written before centrelines were kept have a null centreline in crosswalk rows."""
    table = map_to_table(ROAD_MAP)
    rows = table.to_pylist()
    for row in rows:
        if row["kind"] == "crosswalk":
            row["centreline"] = None
    older = pa.Table.from_pylist(rows, schema=table.schema)
    assert not map_from_table(older).orients("crossing")


def test_an_older_map_table_has_the_optional_layers_it_holds_nothing_of_unknown():
    """Layout 1 (before layers were told apart) took a layer without elements to be unknown."""
    table = map_to_table(replace(ROAD_MAP, unknown_layers=frozenset()))
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    meta["layout"] = 1
    del meta["unknown_layers"]
    older = table.replace_schema_metadata({METADATA_KEY: json.dumps(meta).encode()})
    # the synthetic map holds crosswalks and curbs, but no sidewalks or shoulders
    assert map_from_table(older).unknown_layers == {"sidewalk", "shoulder"}


def test_only_optional_layers_may_be_unknown():
    with pytest.raises(ValueError, match="only crossing, sidewalk, curb, shoulder may be unknown"):
        replace(ROAD_MAP, unknown_layers=frozenset({"lane"}))


def test_point_queries_reuse_the_lane_pairs_they_are_given():
    road_map = synthetic_map()
    rng = np.random.default_rng(3)
    x, y, heading = rng.uniform(-5, 9, 300), rng.uniform(-5, 110, 300), rng.uniform(-3, 3, 300)
    pairs = road_map.lanes_containing(x, y)
    assert np.array_equal(road_map.lane_at(x, y, heading, pairs=pairs), road_map.lane_at(x, y, heading))
    assert np.array_equal(road_map.in_intersection(x, y, pairs=pairs), road_map.in_intersection(x, y))
    for region in ("lane", "drivable"):
        assert np.array_equal(road_map.contains(region, x, y, pairs=pairs), road_map.contains(region, x, y))
