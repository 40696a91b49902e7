"""Each semantic rule of the scene query, on hand-built frames of the synthetic map.

The map (tests/model/maps.py): northbound lanes n1 (x 0..3.5) and n2 (x 3.5..7), southbound
s1 (x -3.5..0), y 0..100; n1b continues n1 to y 200; an eastbound intersection lane x1 crosses
at y 50..53.5; a crosswalk at y 60..63; a curb along x = -3.5. Headings: 0 is north (+y),
π/2 west, π south, -π/2 east. Expected answers are worked out by hand in each test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions
from scenegrep.scene.geometry import geometry_of
from scenegrep.scene.regions import MapRegion
from tests.scene.frames import MAP, ahead, matches, right

NORTH, SOUTH, EAST, WEST = 0.0, math.pi, -math.pi / 2, math.pi / 2
EGO = ("Car", 1.75, 20.0, NORTH)  # centred in lane n1

PERMISSIVE = SceneOptions(unknown_layers=UnknownLayers("permissive"))
"""The synthetic map's unknown layers (sidewalks, shoulders) taken as everywhere."""


def ego(**changes) -> tuple:
    x, y, h = changes.get("x", 1.75), changes.get("y", 20.0), changes.get("h", NORTH)
    return ("Car", x, y, h)


# ---------------------------------------------------------------------------- positions on regions, road direction
def test_on_road_and_its_direction():
    program = "ego = new Car on road"
    assert matches(program, {"ego": EGO}) == [True]
    assert matches(program, {"ego": ego(x=30.0)}) == [False]  # off every lane
    assert matches(program, {"ego": ego(h=0.01)}) == [False]  # heading must be the road direction
    assert matches(program, {"ego": ego(h=0.01)}, heading=0.02) == [True]  # ... within tolerance
    assert matches(program, {"ego": ego(x=-1.75, h=SOUTH)}) == [True]  # southbound lane


def test_road_direction_inside_an_intersection_is_any_lane_direction():
    program = "ego = new Car on road"
    assert matches(program, {"ego": ego(y=51.0, h=NORTH)}, {"ego": ego(y=51.0, h=EAST)}) == [True, True]
    assert matches(program, {"ego": ego(y=51.0, h=WEST)}) == [False]


def test_in_intersection_and_require_not_in_intersection():
    assert matches("ego = new Car in intersection", {"ego": ego(y=51.75, h=EAST)}) == [True]
    assert matches("ego = new Car in intersection", {"ego": EGO}) == [False]
    program = "ego = new Car on road\nrequire not (ego in intersection)"
    # 'in' tests the whole box (Scenic's containsObject): a car straddling the intersection edge is not in it
    assert matches(program, {"ego": EGO}, {"ego": ego(y=51.75)}, {"ego": ego(y=49.0)}) == [True, True, True]
    program = "ego = new Car on road\nrequire ego.position in intersection"
    assert matches(program, {"ego": EGO}, {"ego": ego(y=51.75)}, {"ego": ego(y=49.0)}) == [False, True, False]


def test_on_curb_takes_the_curb_direction():
    program = "spot = new OrientedPoint on curb\nego = new Car at spot, facing spot.heading"
    # the curb runs from y = 0 to y = 100 along x = -3.5 (north); spot takes its direction
    assert matches(program, {"ego": ego(x=-3.5, y=40.0)}) == [True]
    assert matches(program, {"ego": ego(x=-3.4, y=40.0)}) == [False]
    assert matches(program, {"ego": ego(x=-3.5, y=40.0, h=0.1)}) == [False]
    # 'at' sets only the position: the car's own heading is then the road's (lane s1 runs south)
    assert matches(
        "spot = new OrientedPoint on curb\nego = new Car at spot", {"ego": ego(x=-3.5, y=40.0, h=SOUTH)}
    ) == [True]


def test_a_default_region_in_an_unknown_layer_is_an_error_or_the_users_choice():
    # the synthetic map publishes crosswalks but no sidewalks, so a pedestrian's default region
    # (sidewalks and crossings) needs the unknown sidewalk layer
    program = "ego = new Car on road\nped = new Pedestrian"
    on_crosswalk = {"ego": EGO, "p": ("Pedestrian", 2.0, 61.5, 1.0)}
    off_crosswalk = {"ego": EGO, "p": ("Pedestrian", 2.0, 70.0, 1.0)}
    with pytest.raises(
        UserError, match="3:7: .*does not publish the sidewalk layer, which the x of Pedestrian ped needs"
    ):
        matches(program, on_crosswalk, unknown_layers=None)
    # permissive: sidewalks everywhere; strict: no sidewalks, so only the crosswalk holds it
    assert matches(program, on_crosswalk, off_crosswalk) == [True, True]
    assert matches(program, on_crosswalk, off_crosswalk, unknown_layers=UnknownLayers("strict")) == [True, False]
    # crossings alone are published: no choice needed (the car's default road-or-shoulder needs shoulders);
    # 'on' the crossings sets the parent orientation to theirs (east), over the class's random default
    program = (
        "ego = new Car on road, with regionContainedIn None\n"
        "ped = new Pedestrian on network.crossingRegion, with regionContainedIn None"
    )
    along = {"ego": EGO, "p": ("Pedestrian", 2.0, 61.5, EAST)}
    off_along = {"ego": EGO, "p": ("Pedestrian", 2.0, 70.0, EAST)}
    assert matches(program, along, off_along, on_crosswalk, unknown_layers=None) == [True, False, False]


# ---------------------------------------------------------------------------- relative placement
def test_ahead_of_means_a_gap_between_the_boxes():
    program = "ego = new Car on road\nother = new Car ahead of ego by Range(4, 10)"
    gap = 4.5 / 2 + 6 + 4.5 / 2  # centres 10.5 m apart: a 6 m gap
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 20 + gap, NORTH)}) == [True]
    too_close = 4.5 + 3.9
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 20 + too_close, NORTH)}) == [False]
    # the labeled sizes are used: a 3 m car 4.5 m ahead of a 4.5 m ego leaves a 0.75 m gap... too small
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 20 + 4.5, NORTH, 3.0, 2.0)}) == [False]
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 20 + 8.0, NORTH, 3.0, 2.0)}) == [True]  # 4.25 m gap
    # a lateral offset or another heading is not an 'ahead of' placement
    assert matches(program, {"ego": EGO, "c": ("Car", 1.80, 20 + gap, NORTH)}) == [False]
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 20 + gap, 0.05)}) == [False]
    assert matches(program, {"ego": EGO, "c": ("Car", 1.80, 20 + gap, NORTH)}, position=0.06) == [True]


@pytest.mark.parametrize(
    ("specifier", "offset"),
    [
        ("behind ego by 3", (0.0, -(4.5 / 2 + 3 + 4.5 / 2))),
        ("left of ego by 1", (-(2 / 2 + 1 + 2 / 2), 0.0)),
        ("right of ego by 1", ((2 / 2 + 1 + 2 / 2), 0.0)),
        ("ahead of ego", (0.0, 4.5)),
        ("offset by (3, 6)", (3.0, 6.0)),
        ("offset along 90 deg by (0, 3)", (-3.0, 0.0)),
    ],
)
def test_directional_specifiers_in_the_ego_frame(specifier, offset):
    """Offsets in the ego's frame (x right, y ahead) of a car turned by 30 degrees."""
    heading = math.radians(30)
    ex, ey = 2.0, 30.0
    x, y = right(*ahead(ex, ey, heading, offset[1]), heading, offset[0])
    if specifier.startswith("offset along"):  # offset along a global heading, not the ego's
        x, y = ex + offset[0], ey + offset[1]
    program = f"ego = new Car at ({ex}, {ey}), facing 30 deg\nc = new Car {specifier}, with regionContainedIn None"
    other = ("Car", x, y, heading)
    assert matches(program, {"ego": ("Car", ex, ey, heading), "c": other}) == [True]
    moved = ("Car", x + 0.01, y, heading)
    assert matches(program, {"ego": ("Car", ex, ey, heading), "c": moved}) == [False]


def test_relative_specifiers_set_the_parent_orientation():
    # 'left of ego' makes the new car's parent orientation the ego's: it must face the same way
    program = "ego = new Car at (2, 30), facing 30 deg\nc = new Car left of ego by 1, with regionContainedIn None"
    heading = math.radians(30)
    x, y = right(2, 30, heading, -3.0)
    assert matches(program, {"ego": ("Car", 2, 30, heading), "c": ("Car", x, y, heading)}) == [True]
    assert matches(program, {"ego": ("Car", 2, 30, heading), "c": ("Car", x, y, NORTH)}) == [False]


def test_beyond_and_apparently_facing():
    # beyond: 5 m past c along the line from ego; Scenic's parent orientation is then global,
    # so 'apparently facing 90 deg' gives heading = (angle from ego to the car) + 90 deg
    program = (
        "ego = new Car at (0, 0), facing 0\nc = new Car at (0, 10), with regionContainedIn None\n"
        "d = new Car beyond c by 5, apparently facing 90 deg, with regionContainedIn None"
    )
    frame = {"ego": ("Car", 0, 0, NORTH), "c": ("Car", 0, 10, NORTH), "d": ("Car", 0, 15, math.pi / 2)}
    assert matches(program, frame) == [True]
    frame["d"] = ("Car", 0, 15, NORTH)
    assert matches(program, frame) == [False]


def test_facing_toward_and_away_from():
    program = (
        "ego = new Car at (0, 0), facing 0\n"
        "p = new Pedestrian at (10, 0), facing toward ego, with regionContainedIn None"
    )
    assert matches(program, {"ego": ("Car", 0, 0, NORTH), "p": ("Pedestrian", 10, 0, WEST)}) == [True]
    assert matches(program, {"ego": ("Car", 0, 0, NORTH), "p": ("Pedestrian", 10, 0, EAST)}) == [False]
    away = program.replace("facing toward", "facing away from")
    assert matches(away, {"ego": ("Car", 0, 0, NORTH), "p": ("Pedestrian", 10, 0, EAST)}) == [True]


def test_facing_a_range_relative_to_the_road():
    program = "ego = new Car on road, facing Range(-10, 10) deg relative to roadDirection"
    assert matches(program, {"ego": ego(h=math.radians(9))}, {"ego": ego(h=math.radians(11))}) == [True, False]
    assert matches(program, {"ego": ego(h=math.radians(-9.9))}) == [True]


def test_following_the_road():
    program = "ego = new Car on road\nc = new Car following roadDirection for 30"
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 50.0, NORTH)}) == [True]
    assert matches(program, {"ego": EGO, "c": ("Car", 1.75, 50.5, NORTH)}) == [False]
    ranged = "ego = new Car on road\nc = new Car following roadDirection for Range(20, 40)"
    assert matches(ranged, {"ego": EGO, "c": ("Car", 1.75, 55.0, NORTH)}) == [True]
    assert matches(ranged, {"ego": EGO, "c": ("Car", 1.75, 65.0, NORTH)}) == [False]


# ---------------------------------------------------------------------------- visibility
def test_visible_places_the_centre_in_the_view_sector():
    # a Car sees 50 m within a 90 degree cone (45 degrees each side of its heading)
    program = "ego = new Car on road\np = new Pedestrian visible, with regionContainedIn None"
    inside = {"ego": EGO, "p": ("Pedestrian", 1.75 - 10, 20 + 11, 0.0)}  # 42 degrees off the axis
    outside = {"ego": EGO, "p": ("Pedestrian", 1.75 - 11, 20 + 10, 0.0)}  # 48 degrees off
    far = {"ego": EGO, "p": ("Pedestrian", 1.75, 20 + 51, 0.0)}
    assert matches(program, inside, outside, far) == [True, False, False]


def test_not_visible():
    program = "ego = new Car on road\np = new Pedestrian not visible, with regionContainedIn everywhere"
    assert matches(program, {"ego": EGO, "p": ("Pedestrian", 1.75, 5.0, 0.0)}) == [True]  # behind the ego
    assert matches(program, {"ego": EGO, "p": ("Pedestrian", 1.75, 40.0, 0.0)}) == [False]  # in view


def test_visible_road_with_a_visible_distance():
    program = "ego = new Car on road, with visibleDistance 30\nc = new Car on visible road"
    assert matches(program, {"ego": EGO, "c": ("Car", 5.25, 45.0, NORTH)}) == [True]
    assert matches(program, {"ego": EGO, "c": ("Car", 5.25, 55.0, NORTH)}) == [False]


# ---------------------------------------------------------------------------- the correspondence
def test_the_correspondence_is_searched_and_injective():
    program = "ego = new Car on road\na = new Car ahead of ego by 2\nb = new Car ahead of a by 2"
    first = ("Car", 1.75, 20 + 6.5, NORTH)
    second = ("Car", 1.75, 20 + 13.0, NORTH)
    assert matches(program, {"ego": EGO, "z": first, "m": second, "far": ("Car", 5.25, 80.0, NORTH)}) == [True]
    # one car cannot play both parts
    assert matches(program, {"ego": EGO, "z": first}) == [False]


def test_the_program_ego_is_the_trace_ego():
    program = "ego = new Car on road\nother = new Car ahead of ego by 2"
    frame = {"ego": ("Car", 1.75, 26.5, NORTH), "c": ("Car", 1.75, 20.0, NORTH)}
    assert matches(program, frame) == [False]  # 'c' is behind the ego, not ahead


def test_classes_must_correspond():
    program = "ego = new Car on road\np = new Pedestrian ahead of ego by 1, with regionContainedIn None"
    pedestrian = ("Pedestrian", 1.75, 20 + 2.25 + 1 + 0.375, NORTH)
    assert matches(program, {"ego": EGO, "p": pedestrian}) == [True]
    assert matches(program, {"ego": EGO, "p": ("Truck", 1.75, 20 + 2.25 + 1 + 0.375, NORTH, 0.75, 0.75)}) == [False]
    vehicle = "ego = new Car on road\nv = new Vehicle ahead of ego by 1"
    assert matches(vehicle, {"ego": EGO, "t": ("Truck", 1.75, 20 + 2.25 + 1 + 4, NORTH)}) == [True]


def test_exact_matching_counts_every_object_in_view():
    program = "ego = new Car on road"
    frame = {"ego": EGO, "c": ("Car", 5.25, 60.0, NORTH)}
    assert matches(program, frame) == [True]
    assert matches(program, frame, exact=True) == [False]
    assert matches(program, frame, exact=True, visible_distance=30) == [True]  # c is 40 m away


def test_known_correspondence():
    program = "ego = new Car on road\na = new Car ahead of ego by 2"
    frame = {"ego": EGO, "x": ("Car", 1.75, 26.5, NORTH), "y": ("Car", 5.25, 26.5, NORTH)}
    assert matches(program, frame, correspondence={"a": "x"}) == [True]
    assert matches(program, frame, correspondence={"a": "y"}) == [False]


# ---------------------------------------------------------------------------- requirements and distributions
def test_requirements_read_labeled_values():
    program = "ego = new Car on road\nc = new Car on road\nrequire (distance from ego to c) < 10"
    near = {"ego": EGO, "c": ("Car", 5.25, 28.0, NORTH)}
    far = {"ego": EGO, "c": ("Car", 5.25, 35.0, NORTH)}
    assert matches(program, near, far) == [True, False]


def test_a_distribution_in_a_requirement_is_existential():
    program = "ego = new Car on road\nc = new Car on road\nrequire (distance from ego to c) < Range(5, 12)"
    assert matches(program, {"ego": EGO, "c": ("Car", 5.25, 31.0, NORTH)}) == [True]  # 11.5 m
    assert matches(program, {"ego": EGO, "c": ("Car", 5.25, 33.0, NORTH)}) == [False]  # 13.5 m


def test_soft_requirements_are_reported_not_enforced():
    from scenegrep.scene import compile_scene
    from tests.scene.frames import HEADER, MAP, trace_of

    query = compile_scene(HEADER + "ego = new Car on road\nrequire[0.5] ego.position.y > 50", "soft.scenic")
    result = query.match(trace_of({"ego": EGO}, {"ego": ego(y=60.0)}), MAP, PERMISSIVE)
    assert result.matched.tolist() == [True, True]
    assert result.soft == {"require ego.position.y > 50": pytest.approx([False, True])}


def test_options_and_shared_variables():
    program = (
        "ego = new Car on road\ngap = Options([2, 6])\na = new Car ahead of ego by gap\nb = new Car ahead of a by gap"
    )
    two = {"ego": EGO, "a": ("Car", 1.75, 26.5, NORTH), "b": ("Car", 1.75, 33.0, NORTH)}
    mixed = {"ego": EGO, "a": ("Car", 1.75, 26.5, NORTH), "b": ("Car", 1.75, 37.0, NORTH)}
    assert matches(program, two, mixed) == [True, False]  # one draw of gap serves both cars


def test_implicit_requirements():
    # two objects may not overlap, unless one allows collisions
    program = "ego = new Car on road\nc = new Car on road"
    overlapping = {"ego": EGO, "c": ("Car", 2.25, 21.0, NORTH)}
    assert matches(program, overlapping) == [False]
    assert matches(program + ", with allowCollisions True", overlapping) == [True]
    # an Object must be visible from the ego (requireVisible), a DrivingObject need not be
    behind = {"ego": EGO, "o": ("Cone", 1.75, 5.0, NORTH)}
    assert matches("ego = new Car on road\no = new Object at (1.75, 5)", behind) == [False]
    assert matches("ego = new Car on road\no = new Object at (1.75, 5), with requireVisible False", behind) == [True]


def test_parameters_are_checked_against_trace_attributes():
    import dataclasses

    from scenegrep.scene import compile_scene
    from tests.scene.frames import HEADER, MAP, trace_of

    query = compile_scene(HEADER + "param weather = Options(['rain', 'fog'])\nego = new Car on road", "p.scenic")
    trace = trace_of({"ego": EGO})
    assert query.match(trace, MAP, PERMISSIVE).matched.tolist() == [True]  # no attribute: not checked
    rainy = dataclasses.replace(trace, attributes={"weather": "rain"})
    sunny = dataclasses.replace(trace, attributes={"weather": "sun"})
    assert query.match(rainy, MAP, PERMISSIVE).matched.tolist() == [True]
    assert query.match(sunny, MAP, PERMISSIVE).matched.tolist() == [False]


def test_loops_create_one_object_per_iteration():
    program = "ego = new Car on road\nfor i in range(2):\n    new Car ahead of ego by 2 + 10 * i"
    frame = {"ego": EGO, "a": ("Car", 1.75, 26.5, NORTH), "b": ("Car", 1.75, 36.5, NORTH)}
    assert matches(program, frame) == [True]
    assert matches(program, {"ego": EGO, "a": ("Car", 1.75, 26.5, NORTH)}) == [False]


def test_the_jointly_dependent_spot_of_fig6():
    program = (
        "spot = new OrientedPoint on curb\n"
        "ego = new Car at (spot offset by (Range(2, 4), Range(5, 10))), with regionContainedIn None\n"
        "sideCar = new Car left of spot by Range(1, 3), with regionContainedIn None"
    )
    # spot at (-3.5, 40) facing north: ego 3 m right and 8 m ahead, sideCar 1 + 2 m left of the curb
    # the ego's own heading is the road's: lane s1 runs south there
    frame = {"ego": ("Car", -0.5, 48.0, SOUTH), "s": ("Car", -3.5 - 3.0, 40.0, NORTH)}
    assert matches(program, frame) == [True]
    # the same ego with sideCar 5 m along the curb from where ego's spot must be: spot cannot serve both
    frame["s"] = ("Car", -6.5, 20.0, NORTH)
    assert matches(program, frame) == [False]


def test_unknown_map_layer_used_explicitly_is_an_error_naming_it_and_the_object():
    with pytest.raises(UserError, match=r"test.scenic:3:\d+: .*does not publish the sidewalk layer, which the x of"):
        matches(
            "ego = new Car on road\np = new Pedestrian on sidewalk, with regionContainedIn None",
            {"ego": EGO, "p": ("Pedestrian", 0, 0, 0)},
            unknown_layers=None,
        )


def test_choice_counts_the_decisions_it_affected():
    choice = UnknownLayers("permissive")
    program = "ego = new Car on road\nped = new Pedestrian"
    # the pedestrian off the crosswalk is decided by the assumption, the one on it is not
    frames = ({"ego": EGO, "p": ("Pedestrian", 2.0, 61.5, 1.0)}, {"ego": EGO, "p": ("Pedestrian", 2.0, 70.0, 1.0)})
    assert matches(program, *frames, unknown_layers=choice) == [True, True]
    assert choice.decisions["sidewalk"] >= 1
    assert "decisions affected: sidewalk" in choice.report()
    # a car's road-or-shoulder: only a box reaching off the lanes (x -4..-2; lanes start at -3.5) needs
    # the unknown shoulders; one across two lanes (x -0.5..1.5) does not
    choice = UnknownLayers("strict")
    frames = ({"ego": ("Car", -3.0, 20.0, NORTH)}, {"ego": ("Car", 0.5, 20.0, NORTH)})
    assert matches("ego = new Car on road, facing 0", *frames, unknown_layers=choice) == [False, True]
    assert choice.decisions == {"shoulder": 1}


@settings(max_examples=60)
@given(st.lists(st.tuples(st.floats(-300, 300), st.floats(-300, 300)), min_size=1, max_size=20))
def test_the_distance_to_a_map_layer_is_the_distance_to_its_union(points):
    """``distance from P to R`` for a map layer: Scenic's distance to the region (0 inside), the
    distance to the union of the layer's polygons."""
    x, y = np.array(points).T
    layers = {
        "lane": list(MAP.lane_polygons),
        "intersection": [a.polygon for a in MAP.intersections] + list(MAP.lane_polygons[MAP.lane_is_intersection]),
        "crossing": [a.polygon for a in MAP.crosswalks],
    }
    for layer, polygons in layers.items():
        union = shapely.union_all(polygons)
        expected = np.full(len(x), np.inf) if union.is_empty else shapely.distance(union, shapely.points(x, y))
        assert geometry_of(MAP).distances(MapRegion(layer), x, y) == pytest.approx(expected, abs=1e-9)
