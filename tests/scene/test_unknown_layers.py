"""Unknown is never "true": map layers a map holds empty, and layers its format does not publish.

Facts read off the raw maps by hand (shapely on the map's own polygons, no query code):

* Town01, road 8 runs along y; on the line y = -200 its western sidewalk ``road8_sidewalk(3,3)``
  covers x 386.018..390.018, then the shoulder x 390.018..390.318, lane ``road8_lane1`` x
  390.318..394.318 and ``road8_lane0`` x 394.318..398.318. Town01 has sidewalks but no crossings.
* Town06 has neither sidewalks nor crossings, so Scenic's walkable region is empty there; Scenic
  3.1.1 refuses a default ``Pedestrian`` on it (``InvalidScenarioError: Container region of
  unnamed Pedestrian is empty``, tried once by hand).
* nuScenes scene-0061 (ScenarioNet) has no crosswalk features: the format publishes none; the
  trace labels 6725 pedestrian states over its 191 frames.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import shapely

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions, compile_scene

pytestmark = pytest.mark.real_data

HEADER = "model scenic.domains.driving.model\n"
EGO = "ego = new Car on road, facing Range(-180, 180) deg, with regionContainedIn None\n"
DEFAULT_PEDESTRIAN = HEADER + EGO + "ped = new Pedestrian\n"
CROSSING_PEDESTRIAN = HEADER + EGO + "ped = new Pedestrian in crossing, with regionContainedIn None\n"
NUSCENES = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl"

SIDEWALK_X = (386.018, 390.018)
LANE1_X = (390.318, 394.318)
EGO_STATE = (396.3, -150.0, 0.0, 4.5, 2.0)  # in road8_lane0
PEDESTRIANS = {
    "on the sidewalk": (388.0, -200.0, 0.0, 0.75, 0.75),
    "on the road": (392.3, -200.0, 0.0, 0.75, 0.75),
    "on the sidewalk, overhanging the road": (390.0, -200.0, 0.0, 1.0, 1.0),
}


@pytest.fixture(scope="module")
def town(maps_dir):
    """A CARLA town's road map by name (read once per module)."""
    return cache(lambda name: readers.read_map(maps_dir / f"{name}.xodr"))


def pedestrian_trace() -> LabelTrace:
    """One frame per entry of :data:`PEDESTRIANS`, each with the ego and that pedestrian."""
    rows = [(f, o, *state) for f, ped in enumerate(PEDESTRIANS.values()) for o, state in enumerate((EGO_STATE, ped))]
    f, o, x, y, h, length, width = (np.array(c) for c in zip(*rows))
    states = StateTable.build(f, o, x, y, h, length=length, width=width)
    n = len(PEDESTRIANS)
    objects = ObjectTable.build(["ego", "ped"], ["car", "pedestrian"])
    return LabelTrace.build("town", np.arange(n), np.arange(n, dtype=float), objects, states, ego="ego")


def test_the_hand_facts_hold_on_town01(town):
    road_map = town("Town01")
    sidewalk = next(a.polygon for a in road_map.sidewalks if a.id == "road8_sidewalk(3,3)")
    lane1 = next(lane.polygon for lane in road_map.lanes if lane.id == "road8_lane1")
    across = shapely.LineString([(380, -200), (400, -200)])
    assert np.allclose(shapely.intersection(sidewalk, across).bounds[::2], SIDEWALK_X, atol=1e-3)
    assert np.allclose(shapely.intersection(lane1, across).bounds[::2], LANE1_X, atol=1e-3)
    assert not road_map.crosswalks and road_map.sidewalks and not road_map.unknown_layers


def test_a_default_pedestrian_on_town01_must_lie_on_the_sidewalk(town):
    # the walkable region is the sidewalks (crossings: published, none); the pedestrian's whole box
    # must lie in it, so only the one fully on the sidewalk matches (the check that this can fail)
    query = compile_scene(DEFAULT_PEDESTRIAN, "ped.scenic")
    result = query.match(pedestrian_trace(), town("Town01"))
    assert result.matched.tolist() == [True, False, False]


def test_a_default_pedestrian_on_town06_is_refused_as_scenic_refuses_it(town):
    query = compile_scene(DEFAULT_PEDESTRIAN, "ped.scenic")
    with pytest.raises(UserError, match=r"ped.scenic:3:7: the container region .* of Pedestrian ped is empty"):
        query.match(pedestrian_trace(), town("Town06"))


def test_an_empty_layer_is_empty_not_unknown(town):
    # Town01 publishes crossings and has none: no pedestrian is in one, and no choice is asked for
    query = compile_scene(CROSSING_PEDESTRIAN, "ped.scenic")
    assert not query.match(pedestrian_trace(), town("Town01")).matched.any()


def test_nuscenes_crosswalks_are_unknown_an_error_unless_chosen(real_data):
    trace = readers.read_trace(real_data / NUSCENES)
    assert "crossing" in readers.read_map(trace.map_source).unknown_layers
    query = compile_scene(CROSSING_PEDESTRIAN, "ped.scenic")
    with pytest.raises(UserError, match=r"ped.scenic:3:7: .*does not publish the crossing layer, which the x of Ped"):
        query.match(trace)
    pedestrians = int((trace.objects.kinds()[trace.states.object] == "pedestrian").sum())
    assert pedestrians == 6725
    for mode, matched in (("permissive", 191), ("strict", 0)):
        choice = UnknownLayers(mode)
        result = query.match(trace, options=SceneOptions(unknown_layers=choice))
        assert int(result.matched.sum()) == matched
        assert choice.decisions == {"crossing": pedestrians}  # every pedestrian state, once


def test_nuscenes_default_pedestrian_names_both_unknown_layers(real_data):
    trace = readers.read_trace(real_data / NUSCENES)
    query = compile_scene(DEFAULT_PEDESTRIAN, "ped.scenic")
    with pytest.raises(UserError, match="does not publish the crossing and sidewalk layers, which the x of Pedestrian"):
        query.match(trace)


def test_cli_error_and_report(real_data, tmp_path, capsys):
    program = tmp_path / "ped.scenic"
    program.write_text(CROSSING_PEDESTRIAN)
    data = real_data / NUSCENES
    assert main(["scene", str(program), str(data)]) == 2  # the lone trace fails; its map is to blame
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"scenegrep: error: {program}:3:7: the road map 'singapore-onenorth'")
    assert "--unknown-layers permissive|strict" in err[0]
    assert main(["scene", str(program), str(data), "--unknown-layers", "permissive", "--no-values", "-q"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err == [
        "scenegrep: --unknown-layers permissive: unknown map layers taken as everywhere; "
        "decisions affected: crossing 6725"
    ]
    assert main(["scene", str(program), str(data), "--unknown-layers", "permissive", "--no-values", "-q"]) == 0
    assert capsys.readouterr().err.splitlines() == err  # a second run in the process counts its own decisions
