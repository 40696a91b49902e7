"""The labeller's Cross rule over a crosswalk layer that is published, empty, or unknown.

A pedestrian walks north at 1.4 m/s along the northbound lane of the worked example's map (x = 0,
y from -5 m, 30 frames at 0.1 s): walking along the lane, not across it, so by the lane evidence it
is not crossing; only a crosswalk under it makes it Cross.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import shapely

from scenegrep.errors import UserError
from scenegrep.label import label_trace
from scenegrep.model import Area, LabelTrace, ObjectTable, StateTable
from scenegrep.model.layers import UnknownLayers
from tests.scenario.worked_example import worked_map

FRAMES = 30
UNDER = replace(worked_map(), crosswalks=(Area("c", shapely.box(-5.25, -10, 1.75, 20)),))
EMPTY = worked_map()
UNKNOWN = replace(worked_map(), unknown_layers=frozenset({"crossing"}))


def walker() -> LabelTrace:
    t = np.arange(FRAMES) * 0.1
    states = StateTable.build(
        frame=np.arange(FRAMES),
        object=np.zeros(FRAMES, dtype=int),
        x=np.zeros(FRAMES),
        y=-5.0 + 1.4 * t,
        heading=np.zeros(FRAMES),
        length=np.full(FRAMES, 0.75),
        width=np.full(FRAMES, 0.75),
    )
    objects = ObjectTable.build(["ped"], ["pedestrian"])
    return LabelTrace.build("walk", np.arange(FRAMES), t, objects, states)


def crossing(road_map, choice: UnknownLayers | None = None) -> list[bool]:
    sets = label_trace(walker(), road_map, unknown_layers=choice).trace.behaviours.sets()
    return ["Cross" in s for s in sets]


def test_a_published_crosswalk_under_the_walker_makes_it_cross():
    assert all(crossing(UNDER))


def test_an_empty_crosswalk_layer_has_no_crosswalk():
    assert not any(crossing(EMPTY))


def test_an_unknown_crosswalk_layer_is_an_error_naming_it():
    with pytest.raises(UserError, match="does not publish the crossing layer, which the labeller's Cross rule"):
        crossing(UNKNOWN)


def test_the_choice_decides_cross_and_counts_every_walking_observation():
    permissive, strict = UnknownLayers("permissive"), UnknownLayers("strict")
    assert crossing(UNKNOWN, permissive) == crossing(UNDER)
    assert crossing(UNKNOWN, strict) == crossing(EMPTY)
    assert permissive.decisions == strict.decisions == {"crossing": FRAMES}


def test_a_vehicle_only_trace_needs_no_choice():
    trace = walker()
    trace = replace(trace, objects=ObjectTable.build(["car"], ["car"]))
    assert label_trace(trace, UNKNOWN).trace.behaviours is not None


@pytest.mark.real_data
def test_label_cli_refuses_nuscenes_without_a_choice_and_reports_one(real_data, tmp_path, capsys):
    """nuScenes publishes no crosswalks and scene-0061 has walking pedestrians: an error naming the
    input and the layer; with a choice, the count of decisions it affected, the same either way and
    at most the pedestrians' and cyclists' observations."""
    from scenegrep.cli.main import main
    from scenegrep.readers import read_trace

    path = real_data / "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl"
    assert main(["label", str(path), "-o", str(tmp_path), "-q"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"scenegrep: error: {path}: the road map 'singapore-onenorth' does")
    counts = []
    for mode in ("strict", "permissive"):
        assert main(["label", str(path), "-o", str(tmp_path), "-q", "--unknown-layers", mode]) == 0
        last = capsys.readouterr().err.splitlines()[-1]
        assert last.startswith(f"scenegrep: --unknown-layers {mode}: unknown map layers taken as ")
        counts.append(int(last.rsplit("crossing ", 1)[1]))
    trace = read_trace(path)
    walking = np.isin(trace.objects.kinds()[trace.states.object], ["pedestrian", "bicycle", "animal"]).sum()
    assert counts[0] == counts[1] and 0 < counts[0] <= walking
