"""ScenarioNet pickles: nuScenes facts from the issue, restricted unpickling, Waymo maps."""

import pickle

import numpy as np
import pytest

from scenegrep.errors import UserError
from scenegrep.readers import scenarionet

NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"


def ego_rows(trace):
    return trace.states.object == trace.object_index(trace.ego)


def test_scene_0061_ego_turns_left(real_data):
    trace = scenarionet.read_trace(real_data / NUSC.format("0061"))
    heading = np.unwrap(trace.states.heading[ego_rows(trace)])
    assert 93 < np.degrees(heading[-1] - heading[0]) < 103  # about +98 degrees: a left turn
    assert trace.n_frames == 191 and np.isclose(trace.duration, 19.0)


def test_scene_0553_ego_does_not_move(real_data):
    trace = scenarionet.read_trace(real_data / NUSC.format("0553"))
    ego = ego_rows(trace)
    xy = np.c_[trace.states.x[ego], trace.states.y[ego]]
    assert np.ptp(xy, axis=0).max() < 0.05 and ego.sum() == trace.n_frames


def test_nuscenes_ego_size_is_length_first(real_data):
    trace = scenarionet.read_trace(real_data / NUSC.format("0103"))
    ego = ego_rows(trace)
    assert np.allclose(trace.states.length[ego], 4.08) and np.allclose(trace.states.width[ego], 1.73)


def test_nuscenes_map_connectors_are_intersection_lanes(real_data):
    path = real_data / NUSC.format("0061")
    road_map = scenarionet.read_map(path)
    raw = scenarionet.load_scenario(path)["map_features"]
    lanes = {k: f for k, f in raw.items() if f["type"].startswith("LANE")}
    assert len(road_map.lanes) == len(lanes) == 460
    assert road_map.lane_is_intersection.sum() == sum("polygon" not in f for f in lanes.values()) == 247
    assert sum(bool(lane.successors) for lane in road_map.lanes) > 400
    trace = scenarionet.read_trace(path)
    inside = np.zeros(ego_rows(trace).sum(), bool)
    inside[road_map.lanes_containing(trace.states.x[ego_rows(trace)], trace.states.y[ego_rows(trace)])[0]] = True
    assert inside.all()


def test_waymo_pickle(real_data):
    trace = scenarionet.read_trace(real_data / "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl")
    assert (trace.n_frames, trace.n_objects, trace.ego) == (199, 45, "51")
    road_map = scenarionet.read_map(real_data / "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl")
    assert len(road_map.crosswalks) == 5 and len(road_map.lanes) == 102


class Exploit:
    def __reduce__(self):
        return (print, ("pwned",))


def test_refuses_code_in_pickles(tmp_path):
    path = tmp_path / "evil.pkl"
    path.write_bytes(pickle.dumps({"tracks": Exploit(), "metadata": {}, "map_features": {}}))
    with pytest.raises(UserError, match="refusing to unpickle global builtins.print"):
        scenarionet.load_scenario(path)


def test_truncated_and_wrong_content(real_data, tmp_path):
    data = (real_data / NUSC.format("0757")).read_bytes()
    (tmp_path / "cut.pkl").write_bytes(data[: len(data) // 3])
    with pytest.raises(UserError, match=r"cut.pkl: not a valid ScenarioNet pickle"):
        scenarionet.read_trace(tmp_path / "cut.pkl")
    (tmp_path / "list.pkl").write_bytes(pickle.dumps([1, 2]))
    with pytest.raises(UserError, match="not a ScenarioNet scenario"):
        scenarionet.read_trace(tmp_path / "list.pkl")
