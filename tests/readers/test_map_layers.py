"""Each reader states which map layers its format publishes (the others are unknown, not empty)."""

from __future__ import annotations

import pytest

from scenegrep import readers

pytestmark = pytest.mark.real_data

AV2_MAP = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede/map"


@pytest.mark.parametrize(
    ("path", "unknown"),
    [
        # nuScenes' ScenarioNet conversion writes no crosswalks; the format has no sidewalks or shoulders
        ("nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl", {"crossing", "sidewalk", "shoulder"}),
        # Waymo's conversion writes crosswalks (this scenario has 5)
        ("waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl", {"sidewalk", "shoulder"}),
        ("waymo_womd/motion_data_one_scenario.tfrecord", {"sidewalk", "shoulder"}),
        ("commonroad_ngsim/USA_Peach-4_8_T-1.xml", {"crossing", "sidewalk", "curb", "shoulder"}),
    ],
)
def test_unknown_layers_per_format(real_data, path, unknown):
    trace = readers.read_trace(real_data / path)
    road_map = readers.read_map(trace.map_source)
    assert road_map.unknown_layers == unknown
    # none of these formats has sidewalk or crosswalk centrelines: their direction is unknown
    assert not road_map.orients("sidewalk") and not road_map.orients("crossing")


def test_av2_publishes_crossings_and_a_drivable_area_only(real_data):
    road_map = readers.read_map(next((real_data / AV2_MAP).glob("log_map_archive_*.json")))
    assert road_map.unknown_layers == {"sidewalk", "curb", "shoulder"}
    assert road_map.crosswalks and road_map.drivable_area is not None
    assert not road_map.orients("crossing")  # AV2 crossings have edges, no centreline: direction unknown


def test_opendrive_publishes_every_layer(maps_dir):
    town06 = readers.read_map(maps_dir / "Town06.xodr")
    assert not town06.unknown_layers and not town06.sidewalks and not town06.crosswalks
    # empty layers: their (empty) sets of directions are known
    assert town06.orients("sidewalk") and town06.orients("crossing")
