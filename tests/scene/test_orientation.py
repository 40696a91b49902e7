"""Sidewalks, crossings and the walkable region are oriented as in Scenic 3.1.1.

Scenic orients each sidewalk and crossing along the segment of its centreline nearest to a point,
and their unions (``sidewalk``, ``crossing``, ``network.walkableRegion``: sidewalks, then
crossings) by the first element containing the point. ``on R`` and ``in R`` set an object's
parent orientation to R's there (priorities 2 and 3), which beats a class default: Scenic's
``Pedestrian`` has ``parentOrientation: Range(0, 360) deg`` and yaw 0, so ``new Pedestrian`` faces
anywhere but ``new Pedestrian on sidewalk`` faces along the sidewalk. ``Object`` and
``OrientedPoint`` have yaw 0 too.

Facts read off the maps by hand: on Town01, ``road8_sidewalk(3,3)`` covers (388, -200) and its
centreline there runs south at heading -3.14138 (Scenic's ``network.sidewalkRegion.orientation``
at that point, printed once; ``tests/readers/test_opendrive.py`` compares the whole map with
Scenic). The synthetic map's sidewalk (x -6..-3.5, tests/test_constructs.py) runs north and its
crosswalk (y 60..63) east.
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
import shapely

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet
from tests.scene.frames import HEADER, MAP, trace_of
from tests.test_constructs import WALKABLE_MAP

SIDEWALK_HEADING = -3.14138  # road8_sidewalk(3,3) at (388, -200) on Town01
EGO = "ego = new Car on road, facing Range(-180, 180) deg, with regionContainedIn None\n"
UNORIENTED = replace(WALKABLE_MAP, sidewalks=(replace(WALKABLE_MAP.sidewalks[0], centreline=None),))
"""The synthetic map with a sidewalk whose direction it does not give (no centreline)."""


@pytest.fixture(scope="module")
def town01(maps_dir):
    return cache(lambda: readers.read_map(maps_dir / "Town01.xodr"))


def frames_at(x: float, y: float, *headings: float) -> list[dict]:
    """One frame per heading: the ego parked on Town01's road 8 and a pedestrian at (x, y)."""
    ego = ("Car", 396.3, -150.0, 0.0)
    return [{"ego": ego, "p": ("Pedestrian", x, y, h)} for h in headings]


def town_matches(program: str, frames: list[dict], road_map) -> list[bool]:
    query = compile_scene(HEADER + program, "walk.scenic")
    options = SceneOptions(Tolerance(position=0.01, heading=1e-3))
    return query.match(trace_of(*frames), road_map, options).matched.tolist()


@pytest.mark.real_data
def test_the_hand_fact_holds_on_town01(town01):
    road_map = town01()
    sidewalk = next(a for a in road_map.sidewalks if a.id == "road8_sidewalk(3,3)")
    assert sidewalk.polygon.contains(shapely.Point(388, -200))
    step = np.diff(sidewalk.centreline, axis=0)
    assert np.any(np.isclose(np.arctan2(-step[:, 0], step[:, 1]), SIDEWALK_HEADING, atol=1e-5))


@pytest.mark.real_data
def test_a_pedestrian_on_the_sidewalk_faces_along_it_on_town01(town01):
    # facing along, across (90 degrees off) and against the sidewalk's direction
    frames = frames_at(388.0, -200.0, SIDEWALK_HEADING, SIDEWALK_HEADING + math.pi / 2, SIDEWALK_HEADING + math.pi)
    on_sidewalk = EGO + "p = new Pedestrian on sidewalk, with regionContainedIn None\n"
    assert town_matches(on_sidewalk, frames, town01()) == [True, False, False]
    walkable = EGO + "p = new Pedestrian on network.walkableRegion, with regionContainedIn None\n"
    assert town_matches(walkable, frames, town01()) == [True, False, False]
    # the class default: a random parent orientation, so any heading
    assert town_matches(EGO + "p = new Pedestrian\n", frames, town01()) == [True, True, True]


@pytest.mark.real_data
def test_an_oriented_point_on_the_sidewalk_orients_what_is_placed_ahead_of_it(town01):
    # the point is random: 1.375 m behind the pedestrian along the heading the point takes there
    program = EGO + "spot = new OrientedPoint on sidewalk\np = new Pedestrian ahead of spot by 1\n"
    frames = frames_at(388.0, -200.0, SIDEWALK_HEADING, SIDEWALK_HEADING + math.pi / 2)
    assert town_matches(program, frames, town01()) == [True, False]


def synthetic_matches(program: str, road_map, mode: str | None, *headings: float) -> list[bool]:
    """The program (after an ego) on the synthetic map, with an object on its sidewalk at each heading."""
    frames = [{"ego": ("Car", 1.75, 20.0, 0.0), "p": ("Pedestrian", -4.75, 30.0, h)} for h in headings]
    query = compile_scene(HEADER + "ego = new Car at (1.75, 20)\n" + program, "test.scenic")
    options = SceneOptions(unknown_layers=UnknownLayers(mode))
    return query.match(trace_of(*frames), road_map, options).matched.tolist()


def test_a_map_that_gives_the_direction_decides_the_heading():
    assert synthetic_matches("p = new Object on sidewalk", WALKABLE_MAP, None, 0.0, math.pi / 2) == [True, False]


def test_a_direction_the_map_does_not_give_is_an_error_naming_the_object():
    with pytest.raises(UserError) as caught:
        synthetic_matches("p = new Object on sidewalk", UNORIENTED, None, 0.0)
    assert caught.value.one_line() == (
        "test.scenic:3:5: the road map 'synthetic' does not give the direction of its sidewalks (no centrelines), "
        "which the heading of Object p needs; say how to treat unknown layers with --unknown-layers permissive|strict"
    )


def test_the_choice_takes_the_unknown_direction_as_any_heading_or_none():
    program = "p = new Object on sidewalk"
    assert synthetic_matches(program, UNORIENTED, "permissive", 0.0, math.pi / 2) == [True, True]
    assert synthetic_matches(program, UNORIENTED, "strict", 0.0, math.pi / 2) == [False, False]
    choice = UnknownLayers("strict")
    query = compile_scene(HEADER + "ego = new Car at (1.75, 20)\n" + program, "test.scenic")
    frame = {"ego": ("Car", 1.75, 20.0, 0.0), "p": ("Pedestrian", -4.75, 30.0, 0.0)}
    query.match(trace_of(frame), UNORIENTED, SceneOptions(unknown_layers=choice))
    assert choice.decisions == {"sidewalk direction": 1}  # the one candidate row, refused
    # the walkable region's direction reads the sidewalks' too
    walkable = "p = new Object on network.walkableRegion"
    assert synthetic_matches(walkable, UNORIENTED, "permissive", 0.0, math.pi / 2) == [True, True]
    assert synthetic_matches(walkable, UNORIENTED, "strict", 0.0, math.pi / 2) == [False, False]


def test_a_program_that_does_not_read_the_direction_needs_no_choice():
    # 'facing' sets the heading itself; a default Pedestrian's parent orientation is random
    facing = "p = new Object on sidewalk, facing 90 deg"
    assert synthetic_matches(facing, UNORIENTED, None, 0.0, math.pi / 2) == [False, True]
    assert synthetic_matches("p = new Pedestrian", UNORIENTED, None, 0.0, math.pi / 2) == [True, True]


def test_the_crossing_direction_on_a_map_whose_crosswalks_have_no_centreline():
    crosswalk = replace(MAP.crosswalks[0], centreline=None)
    road_map = replace(WALKABLE_MAP, crosswalks=(crosswalk,))
    program = "ego = new Car at (1.75, 20)\np = new Object on crossing"
    frame = {"ego": ("Car", 1.75, 20.0, 0.0), "p": ("Pedestrian", 1.75, 61.5, -math.pi / 2)}
    assert compile_scene(HEADER + program).match(trace_of(frame), WALKABLE_MAP).matched.tolist() == [True]
    with pytest.raises(UserError, match=r"3:5: .*does not give the direction of its crossings"):
        compile_scene(HEADER + program).match(trace_of(frame), road_map)


def test_cli_error_is_one_line_and_the_choice_is_reported(tmp_path, capsys):
    (tmp_path / "p.scenic").write_text(HEADER + "ego = new Car at (1.75, 20)\np = new Object on sidewalk\n")
    write_trace_json(
        trace_of({"ego": ("Car", 1.75, 20.0, 0.0), "p": ("Pedestrian", -4.75, 30.0, 1.0)}), tmp_path / "t.json"
    )
    write_map_parquet(UNORIENTED, tmp_path / "map.parquet")
    args = ["scene", str(tmp_path / "p.scenic"), str(tmp_path / "t.json"), "--map", str(tmp_path / "map.parquet")]
    assert main(args) == 2  # the lone trace fails: its map lacks the direction
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("scenegrep: error: ")
    assert err[0].endswith("--unknown-layers permissive|strict")
    assert "p.scenic:3:5: the road map 'synthetic' does not give the direction of its sidewalks" in err[0]
    assert main([*args, "--unknown-layers", "permissive", "-q", "--no-values"]) == 0
    assert capsys.readouterr().err.splitlines()[-1].startswith("scenegrep: --unknown-layers permissive")
    assert main([*args, "--unknown-layers", "strict", "-q", "--no-values"]) == 1
    assert "decisions affected: sidewalk direction 1" in capsys.readouterr().err
