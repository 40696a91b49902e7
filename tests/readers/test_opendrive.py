"""OpenDRIVE maps through Scenic's network, and the map cache."""

import sys

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.readers import opendrive
from scenegrep.scene.geometry import MapGeometry
from scenegrep.scene.regions import MapField


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SCENEGREP_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


@pytest.mark.slow
def test_town01_facts_and_cache(maps_dir, cache):
    road_map = opendrive.read_map(maps_dir / "Town01.xodr")
    # docs/scenic-reference.md: Town01 has 124 lanes, 26 roads, 72 connecting roads, 12 intersections
    assert (len(road_map.lanes), len(road_map.roads), len(road_map.intersections)) == (124, 26, 12)
    assert road_map.lane_is_intersection.sum() == 72  # one lane per connecting road
    assert opendrive.cached_map_path(maps_dir / "Town01.xodr").is_file()
    again = opendrive.read_map(maps_dir / "Town01.xodr")
    assert again.equals(road_map)
    # a point on road0_lane0's centreline has the lane's direction of travel
    lane = road_map.lanes[road_map.lane_index["road0_lane0"]]
    mid = lane.centreline.mean(axis=0)  # a straight two-point lane
    found = road_map.lane_at(np.array([mid[0]]), np.array([mid[1]]))[0]
    assert road_map.lanes[found].id == "road0_lane0"


SCENIC_NETWORK = pytest.mark.xdist_group("town01-scenic-network")
"""The tests reading Scenic's own Town01 network run in one test process (``--dist loadgroup``),
which parses it once (seconds), instead of once in each process that runs one of them."""


@pytest.fixture(scope="module")
def town01_with_scenic(maps_dir, tmp_path_factory):
    """Town01 as our map and as Scenic's own network (the reference), parsed once per module."""
    from scenic.domains.driving.roads import Network

    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SCENEGREP_CACHE", str(tmp_path_factory.mktemp("cache")))
        road_map = opendrive.read_map(maps_dir / "Town01.xodr")
    network = Network.fromFile(str(maps_dir / "Town01.xodr"), useCache=False, writeCache=False)
    return road_map, network


@pytest.mark.slow
@SCENIC_NETWORK
def test_scenic_directions_agree(town01_with_scenic):
    """Our lane direction equals Scenic's own orientation (the oracle) in the middle of every
    centreline segment longer than 25 cm, on every lane of Town01."""
    from scenic.core.vectors import Vector

    road_map, network = town01_with_scenic
    checked = 0
    for lane in network.lanes:
        pts = np.asarray(lane.centerline.points)[:, :2]
        long = np.flatnonzero(np.hypot(*np.diff(pts, axis=0).T) > 0.25)
        mids = (pts[long] + pts[long + 1]) / 2
        ours = road_map.lane_direction_at(mids[:, 0], mids[:, 1], np.full(len(mids), road_map.lane_index[lane.uid]))
        theirs = np.array([lane.orientation[Vector(*p)].yaw for p in mids])
        assert np.all(np.abs(np.angle(np.exp(1j * (ours - theirs)))) < 0.02), lane.uid
        checked += len(mids)
    assert checked > 2000


def _scenic_yaw(region, x: float, y: float) -> float:
    from scenic.core.vectors import Vector

    return region.orientation[Vector(x, y)].yaw


def _angle(a, b):
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b)))))


@pytest.mark.slow
@SCENIC_NETWORK
def test_town01_sidewalks_come_with_scenic_centrelines_in_scenic_order(town01_with_scenic):
    road_map, network = town01_with_scenic
    assert [a.id for a in road_map.sidewalks] == [s.uid for s in network.sidewalks]
    assert len(road_map.sidewalks) == 64 and road_map.orients("sidewalk")
    # Scenic 3.1.1's OpenDRIVE parser makes no crossings: the layer is published and empty
    assert not road_map.crosswalks and not network.crossings and road_map.orients("crossing")
    for ours, theirs in zip(road_map.sidewalks, network.sidewalks):
        assert np.array_equal(ours.centreline, np.asarray(theirs.centerline.points)[:, :2])


@pytest.mark.slow
@SCENIC_NETWORK
def test_sidewalk_directions_equal_scenics_at_random_points(town01_with_scenic):
    """Scenic's network.sidewalkRegion and walkableRegion orientations (a union: the first sidewalk
    containing the point) at 5000 uniform points of Scenic's sidewalk region, against ours."""
    road_map, network = town01_with_scenic
    geometry = MapGeometry(road_map)
    polygon = network.sidewalkRegion.polygons
    x0, y0, x1, y1 = polygon.bounds
    rng = np.random.default_rng(15)
    x, y = rng.uniform(x0, x1, 400_000), rng.uniform(y0, y1, 400_000)
    inside = shapely.contains_xy(polygon, x, y)
    x, y = x[inside][:5000], y[inside][:5000]
    assert len(x) == 5000
    for name, region in (("sidewalk", network.sidewalkRegion), ("walkable", network.walkableRegion)):
        rows, ours = geometry.field_values(MapField(name), x, y, None)
        assert np.array_equal(rows, np.arange(len(x)))
        theirs = [_scenic_yaw(region, *p) for p in zip(x, y)]
        assert np.all(_angle(ours, theirs) < 1e-9), name


@pytest.mark.slow
@SCENIC_NETWORK
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(element=st.integers(0, 63), along=st.floats(0, 1), across=st.floats(-3, 3))
def test_sidewalk_direction_near_any_centreline_is_scenics(town01_with_scenic, element, along, across):
    """Points across each sidewalk (and just past its edges, into Scenic's union's slivers): our
    direction, and the headings the interval solver allows in a 2 cm box around the point, hold
    Scenic's."""
    road_map, network = town01_with_scenic
    line = shapely.LineString(network.sidewalks[element].centerline.points)
    here, ahead = line.interpolate(along, normalized=True), line.interpolate(min(along + 1e-3, 1), normalized=True)
    normal = np.array([-(ahead.y - here.y), ahead.x - here.x])
    if along == 1 or not np.hypot(*normal):
        normal = np.array([0.0, 1.0])
    px, py = np.array([here.x, here.y]) + across * normal / np.hypot(*normal)
    assume(network.sidewalkRegion.containsPoint((px, py)))
    geometry = MapGeometry(road_map)
    theirs = _scenic_yaw(network.sidewalkRegion, px, py)
    assert _angle(geometry.field_values(MapField("sidewalk"), np.array([px]), np.array([py]), None)[1], theirs) < 1e-9
    allowed = geometry.field_headings_in_box(MapField("sidewalk"), px - 0.01, px + 0.01, py - 0.01, py + 0.01, None)
    assert np.min(_angle(allowed, theirs)) < 1e-9


def test_truncated_file_is_a_user_error(maps_dir, cache, tmp_path):
    data = (maps_dir / "Town01.xodr").read_bytes()
    (tmp_path / "cut.xodr").write_bytes(data[: len(data) // 2])
    with pytest.raises(UserError, match=r"cut.xodr: not a valid OpenDRIVE file"):
        opendrive.read_map(tmp_path / "cut.xodr")


def test_cached_map_loads_without_scenic(maps_dir, cache):
    import subprocess

    opendrive.read_map(maps_dir / "Town01.xodr")
    code = (
        "import sys; from scenegrep.readers import opendrive; "
        f"opendrive.read_map({str(maps_dir / 'Town01.xodr')!r}); print('scenic' in sys.modules)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={"SCENEGREP_CACHE": str(cache), "PATH": "/usr/bin"},
    )
    assert out.stdout.strip() == "False"
