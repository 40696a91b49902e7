"""OpenDRIVE maps through Scenic's network, and the map cache."""

import sys

import numpy as np
import pytest

from scenegrep.errors import UserError
from scenegrep.readers import opendrive


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


@pytest.mark.slow
def test_scenic_directions_agree(maps_dir, cache):
    """Our lane direction equals Scenic's own orientation (the oracle) in the middle of every
    centreline segment longer than 25 cm, on every lane of Town01."""
    from scenic.core.vectors import Vector
    from scenic.domains.driving.roads import Network

    road_map = opendrive.read_map(maps_dir / "Town01.xodr")
    network = Network.fromFile(str(maps_dir / "Town01.xodr"), useCache=False, writeCache=False)
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
