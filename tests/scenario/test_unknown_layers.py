"""Scenario guards and the initial scene over map layers: empty, published, or unknown.

The map is the worked example's two northbound lanes (x -5.25..1.75, y -60..60) with, or without,
a crosswalk across them at y 10..13. The pedestrian stands at (0, 0), outside that crosswalk, and is
labelled Stationary throughout; its behaviour stays Stationary until it is in a crossing, then
follows a lane for ever (FollowLane, which the labels never show). So the program matches exactly
when the guard ``self.position in crossing`` is false at the pedestrian's place: on a map whose
crosswalk is elsewhere, on one that publishes no crosswalk with the strict choice (none), and not
with the permissive one (crosswalks everywhere).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import shapely

from scenegrep.errors import UserError
from scenegrep.model import Area, BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.model.layers import UnknownLayers
from scenegrep.scenario import ScenarioOptions, compile_scenario

from .worked_example import worked_map

PROGRAM = """model scenic.domains.driving.model
behavior WaitToCross():
    do StationaryBehavior() until self.position in crossing
    do FollowLaneBehavior()
ego = new Car on road, facing Range(-180, 180) deg, with regionContainedIn None
ped = new Pedestrian on road, facing Range(-180, 180) deg, with regionContainedIn None, with behavior WaitToCross()
"""
CROSSWALK = Area("c", shapely.box(-5.25, 10, 1.75, 13))
PUBLISHED = replace(worked_map(), crosswalks=(CROSSWALK,))
EMPTY = worked_map()
UNKNOWN = replace(worked_map(), unknown_layers=frozenset({"crossing"}))


def waiting_trace(frames: int = 4) -> LabelTrace:
    """The ego at (0, -30) and the pedestrian at (0, 0), both Stationary, for ``frames`` frames."""
    frame = np.repeat(np.arange(frames), 2)
    states = StateTable.build(
        frame=frame,
        object=np.tile([0, 1], frames),
        x=np.zeros(2 * frames),
        y=np.tile([-30.0, 0.0], frames),
        heading=np.zeros(2 * frames),
        length=np.tile([4.5, 0.75], frames),
        width=np.tile([2.0, 0.75], frames),
    )
    labels = BehaviourLabels.from_sets([{"Stationary"}] * (2 * frames))
    objects = ObjectTable.build(["ego", "ped"], ["car", "pedestrian"])
    return LabelTrace.build("wait", np.arange(frames), np.arange(frames) * 0.1, objects, states, ego="ego",
                            behaviours=labels)  # fmt: skip


def matched(road_map, mode: str | None = None) -> bool:
    query = compile_scenario(PROGRAM, "wait.scenic")
    return query.match(waiting_trace(), "all", road_map, ScenarioOptions(unknown_layers=UnknownLayers(mode))).matched


def test_a_published_crosswalk_elsewhere_keeps_the_guard_false():
    assert matched(PUBLISHED)


def test_an_empty_crossing_layer_is_empty():
    assert matched(EMPTY)


def test_an_unknown_crossing_layer_in_a_guard_is_an_error_naming_it():
    with pytest.raises(UserError, match=r"wait.scenic:3:\d+: .*does not publish the crossing layer, which the guard"):
        matched(UNKNOWN)


def test_the_choice_decides_the_guard_and_is_counted():
    assert not matched(UNKNOWN, "permissive")  # in a crossing at once: must move on, but stands
    assert matched(UNKNOWN, "strict")
    choice = UnknownLayers("strict")
    query = compile_scenario(PROGRAM, "wait.scenic")
    query.match(waiting_trace(), "all", UNKNOWN, ScenarioOptions(unknown_layers=choice))
    assert choice.decisions["crossing"] >= 1


def test_the_initial_scene_takes_the_same_rule():
    # a pedestrian with Scenic's default container (sidewalks and crossings) on a map that publishes
    # no sidewalks: an error without a choice; permissive: it may stand anywhere; strict: only the
    # crosswalk is walkable, and the pedestrian stands outside it
    program = PROGRAM.replace(", with regionContainedIn None, with behavior", ", with behavior")
    query = compile_scenario(program, "wait.scenic")

    def run(road_map, mode):
        options = ScenarioOptions(unknown_layers=UnknownLayers(mode))
        return query.match(waiting_trace(), "all", road_map, options).matched

    no_sidewalks = replace(PUBLISHED, unknown_layers=frozenset({"sidewalk"}))
    with pytest.raises(UserError, match="does not publish the sidewalk layer"):
        run(no_sidewalks, None)
    assert run(no_sidewalks, "permissive")
    assert not run(no_sidewalks, "strict")
    # a map that publishes both layers and holds neither has no walkable region: refused, as Scenic does
    with pytest.raises(UserError, match="the container region .* of Pedestrian ped is empty"):
        run(EMPTY, None)


def test_the_initial_scene_takes_the_crossings_direction_by_the_same_rule():
    # the pedestrian stands on a crosswalk facing north; 'on crossing' orients it along the crosswalk:
    # a centreline running north decides it, one running east refuses it; without a centreline the
    # direction is unknown: an error without a choice, any heading (permissive) or none (strict)
    program = PROGRAM.replace(
        "ped = new Pedestrian on road, facing Range(-180, 180) deg,", "ped = new Pedestrian on crossing,"
    ).replace("with behavior WaitToCross()", "with behavior StationaryBehavior()")
    query = compile_scenario(program, "wait.scenic")
    here = shapely.box(-1, -2, 1, 2)

    def run(centreline, mode=None):
        road_map = replace(worked_map(), crosswalks=(Area("c", here, centreline=centreline),))
        options = ScenarioOptions(unknown_layers=UnknownLayers(mode))
        return query.match(waiting_trace(), "all", road_map, options).matched

    assert run(np.array([[0.0, -2], [0, 2]]))
    assert not run(np.array([[-1.0, 0], [1, 0]]))
    with pytest.raises(UserError, match=r"wait.scenic:6:7: .*does not give the direction of its crossings"):
        run(None)
    assert run(None, "permissive")
    assert not run(None, "strict")
