"""Argoverse 2: sensor logs (facts from the issue), forecasting scenarios, maps."""

import numpy as np
import pyarrow.feather as feather
import pytest

from scenegrep.errors import UserError
from scenegrep.model.geometry import heading_from_yaw, yaw_from_quaternion
from scenegrep.readers import av2_forecasting, av2_map, av2_sensor, read_map

LOG = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
OTHER_LOG = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"
SCENARIO = "av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151"


@pytest.fixture(scope="module")
def log_trace(real_data):
    return av2_sensor.read_trace(real_data / LOG)


def test_sensor_log_counts(log_trace):
    annotated = log_trace.states.object != log_trace.object_index("ego")
    assert annotated.sum() == 11_364
    assert log_trace.n_frames == 156
    assert log_trace.n_objects - 1 == 114
    assert len(set(log_trace.objects.category[log_trace.objects.id != "ego"])) == 10
    assert log_trace.ego == "ego" and np.isclose(log_trace.duration, 15.5, atol=0.05)


def test_sensor_map_counts_and_ego_in_lane(log_trace):
    road_map = read_map(log_trace.map_source)
    assert len(road_map.lanes) == 183 and road_map.lane_is_intersection.sum() == 73
    ego = log_trace.states.object == log_trace.object_index("ego")
    point_idx, _ = road_map.lanes_containing(log_trace.states.x[ego], log_trace.states.y[ego])
    assert len(np.unique(point_idx)) == 156


def test_pose_transform_of_one_box(real_data, log_trace):
    """One box checked by hand: city = R_ego · box + t_ego, yaw_city = yaw_ego + yaw_box (planar)."""
    ann = feather.read_table(real_data / LOG / "annotations.feather").slice(0, 1).to_pylist()[0]
    poses = feather.read_table(real_data / LOG / "city_SE3_egovehicle.feather").to_pylist()
    pose = next(p for p in poses if p["timestamp_ns"] == ann["timestamp_ns"])
    yaw_ego = yaw_from_quaternion(pose["qw"], pose["qx"], pose["qy"], pose["qz"])
    c, s = np.cos(yaw_ego), np.sin(yaw_ego)
    x = pose["tx_m"] + c * ann["tx_m"] - s * ann["ty_m"]
    y = pose["ty_m"] + s * ann["tx_m"] + c * ann["ty_m"]
    row = np.flatnonzero(
        (log_trace.states.frame == 0) & (log_trace.objects.id[log_trace.states.object] == ann["track_uuid"])
    )[0]
    # the ego has small roll/pitch, so a planar check agrees to a few centimetres
    assert abs(log_trace.states.x[row] - x) < 0.1 and abs(log_trace.states.y[row] - y) < 0.1
    yaw_box = yaw_from_quaternion(ann["qw"], ann["qx"], ann["qy"], ann["qz"])
    assert abs(np.angle(np.exp(1j * (log_trace.states.heading[row] - heading_from_yaw(yaw_ego + yaw_box))))) < 0.02


def test_other_log_and_forecasting(real_data):
    other = av2_sensor.read_trace(real_data / OTHER_LOG)
    assert (other.states.object != other.object_index("ego")).sum() == 12_078 and other.n_objects - 1 == 146
    scenario = av2_forecasting.read_trace(real_data / SCENARIO)
    assert (scenario.n_frames, scenario.n_objects, scenario.ego) == (110, 58, "AV")
    assert np.isclose(scenario.duration, 10.9)
    assert scenario.attributes["city"] == "austin"
    assert len(av2_map.read_map(scenario.map_source.path).lanes) == 71


def test_truncated_annotations(real_data, tmp_path):
    log = tmp_path / "log"
    log.mkdir()
    for name in ("annotations.feather", "city_SE3_egovehicle.feather"):
        data = (real_data / LOG / name).read_bytes()
        (log / name).write_bytes(data[: len(data) // 2] if name.startswith("ann") else data)
    with pytest.raises(UserError, match=r"annotations.feather: not a valid Argoverse 2 feather file"):
        av2_sensor.read_trace(log)
