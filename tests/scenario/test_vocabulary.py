"""The behaviour vocabulary for real data (issue 16): sided turns and lane changes, the labeller's
behaviours by name, and the "any behaviour" primitive beside Scenic's rule that an object without
a behaviour stands still. Small hand-built label traces; the real-data checks are in
``test_vocabulary_real_data.py`` and the labeller's side identities in ``tests/label/test_sides.py``.
"""

from __future__ import annotations

import importlib.util
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, RoadMap, StateTable
from scenegrep.model.layers import UnknownLayers
from scenegrep.scenario import ScenarioOptions, ScenarioQuery, compile_scenario, load_scenario
from scenegrep.scenario.vocabulary import load_vocabulary, read_vocabulary
from tests.model.maps import synthetic_map

from .reference import reference_matches
from .test_search import traces
from .worked_example import worked_map, worked_trace

HEADER = "model scenic.simulators.newtonian.driving_model\n"
VEHICLE_PRIMITIVES = ["TurnLeft", "TurnRight", "LaneChangeLeft", "LaneChangeRight", "Brake", "Accelerate", "Reverse"]
"""Named primitives a vehicle's label set (from ``scenegrep label``) can hold, beside FollowLane."""


def matched_ids(program: str, trace: LabelTrace, road_map, window: int, options=None) -> set[str]:
    """Ids of the label objects the program's ego corresponds to in some matching window."""
    options = options or ScenarioOptions(find_all=True)
    result = compile_scenario(program).match(trace, window, road_map=road_map, options=options)
    return {match.correspondence["ego"] for match in result.matches}


def ego_program(primitive: str, spelling: str, kind: str = "Car") -> str:
    """``ego`` runs ``primitive``: called directly by its Scenic-style name, or from a behaviour."""
    if spelling == "direct":
        return HEADER + f"ego = new {kind} with behavior {primitive}Behavior()\n"
    return HEADER + f"behavior B():\n    do {primitive}()\nego = new {kind} with behavior B()\n"


@pytest.mark.parametrize("spelling", ["direct", "do"])
@pytest.mark.parametrize("primitive", VEHICLE_PRIMITIVES)
def test_vehicle_primitives_consume_the_frames_labelled_so(primitive, spelling):
    # car2 moves (never Stationary), so only its own label can carry it through the window.
    program = ego_program(primitive, spelling)
    assert "car2" in matched_ids(program, worked_trace([primitive] * 5), worked_map(), 5)
    for other in ["FollowLane", *VEHICLE_PRIMITIVES]:
        if other != primitive:
            assert "car2" not in matched_ids(program, worked_trace([other] * 5), worked_map(), 5), other


@pytest.mark.parametrize("primitive", VEHICLE_PRIMITIVES)
def test_the_labellers_names_never_end_by_themselves(primitive):
    # a primitive that can end may end before its first step, and an object that stands still
    # would then match it; the labeller's names last until a `for`, `until` or interrupt ends them
    assert not load_vocabulary().primitive(primitive).ends
    program = ego_program(primitive, "do")
    assert "car1" not in matched_ids(program, worked_trace([primitive] * 5), worked_map(), 5)
    assert "car1" in matched_ids(ego_program("Turn", "do"), worked_trace([primitive] * 5), worked_map(), 5)
    bounded = HEADER + (
        f"behavior B():\n    do {primitive}Behavior() for 2 steps\n    do FollowLaneBehavior()\n"
        "ego = new Car with behavior B()\n"
    )
    assert "car2" in matched_ids(bounded, worked_trace([primitive] * 2 + ["FollowLane"] * 3), worked_map(), 5)
    assert "car2" not in matched_ids(bounded, worked_trace([primitive] + ["FollowLane"] * 4), worked_map(), 5)


def pedestrian_trace(labels: list[set[str]]) -> LabelTrace:
    """One pedestrian walking east through the synthetic map's crosswalk, one label set per frame."""
    n = len(labels)
    states = StateTable.build(
        frame=np.arange(n), object=np.zeros(n, dtype=np.int64), x=np.linspace(0.0, 2.0, n), y=np.full(n, 61.5),
        heading=np.full(n, -np.pi / 2), length=np.full(n, 0.5), width=np.full(n, 0.5),
    )  # fmt: skip
    objects = ObjectTable.build(["walker"], ["pedestrian"])
    behaviours = BehaviourLabels.from_sets(labels)
    return LabelTrace.build("walk", np.arange(n), np.arange(n) * 0.5, objects, states, behaviours=behaviours)


@pytest.mark.parametrize("spelling", ["direct", "do"])
@pytest.mark.parametrize(("primitive", "other"), [("Walk", "Cross"), ("Cross", "Walk")])
def test_pedestrian_primitives_consume_the_frames_labelled_so(primitive, other, spelling):
    # the synthetic map publishes no sidewalks: taken as none, its crosswalk is the walkable region
    options = ScenarioOptions(find_all=True, unknown_layers=UnknownLayers("strict"))
    program = ego_program(primitive, spelling, "Pedestrian")
    assert matched_ids(program, pedestrian_trace([{primitive}] * 4), synthetic_map(), 4, options) == {"walker"}
    assert matched_ids(program, pedestrian_trace([{other}] * 4), synthetic_map(), 4, options) == set()
    mixed = [{primitive}, {primitive}, {other}, {primitive}]
    assert matched_ids(program, pedestrian_trace(mixed), synthetic_map(), 4, options) == set()


@pytest.mark.parametrize(
    ("whole", "sides"), [("Turn", ("TurnLeft", "TurnRight")), ("LaneChange", ("LaneChangeLeft", "LaneChangeRight"))]
)
def test_a_side_is_one_half_of_the_unsided_primitive(whole, sides):
    left, right = sides
    for label in sides:
        assert "car2" in matched_ids(ego_program(whole, "do"), worked_trace([label] * 5), worked_map(), 5)
    assert "car2" not in matched_ids(ego_program(left, "do"), worked_trace([right] * 5), worked_map(), 5)
    assert "car2" not in matched_ids(ego_program(right, "do"), worked_trace([left] * 5), worked_map(), 5)
    # Scenic-simulated ground truth names no side: a sided primitive does not claim it
    assert "car2" not in matched_ids(ego_program(left, "do"), worked_trace([whole] * 5), worked_map(), 5)
    vocabulary = load_vocabulary()
    assert vocabulary.primitive(whole).labels == {whole, left, right}
    assert vocabulary.primitive(left).labels == {left} and vocabulary.primitive(right).labels == {right}


FIG1 = Path("examples/queries/fig1_lane_change.scenic")


def fig1_with_any() -> str:
    text = FIG1.read_text(encoding="utf-8")
    without = 'otherCar = new Car on visible ego.lane, with name "otherCar"'
    assert without in text
    return text.replace(without, without + ", with behavior AnyBehavior()")


def test_any_behaviour_matches_a_moving_object_the_default_refuses():
    # Table 2 with the other car moving (FollowLane) instead of standing: Scenic's rule (no behaviour,
    # so Stationary) refuses it; AnyBehavior says its behaviour does not matter.
    moving = worked_trace(car1_label="FollowLane")
    default = load_scenario(FIG1).match(moving, 5, road_map=worked_map())
    assert not default.matched
    anything = compile_scenario(fig1_with_any()).match(moving, 5, road_map=worked_map())
    assert anything.matched and anything.matches[0].correspondence == {"ego": "car2", "otherCar": "car1"}
    # and it still admits the standing car, as the default does
    assert compile_scenario(fig1_with_any()).match(worked_trace(), 5, road_map=worked_map()).matched


@cache
def any_query_and_map() -> tuple[ScenarioQuery, RoadMap]:
    """Figure 1 with AnyBehavior, compiled once, and the worked example's map (one query over many
    traces and one map, as a run over a dataset uses them)."""
    return compile_scenario(fig1_with_any()), worked_map()


@settings(max_examples=100, deadline=None)
@given(traces(), st.integers(1, 5))
def test_any_behaviour_agrees_with_the_brute_force_reference(trace, m):
    query, road_map = any_query_and_map()
    result = query.match(trace, m, road_map=road_map, options=ScenarioOptions(find_all=True))
    fast = {(tuple(sorted(match.correspondence.items())), int(s)) for match in result.matches for s in match.starts}
    assert fast == reference_matches(query, trace, m, road_map=road_map)


def test_any_behaviour_admits_every_label_set_also_an_empty_one():
    program = ego_program("Any", "direct", "Pedestrian")
    options = ScenarioOptions(find_all=True, unknown_layers=UnknownLayers("strict"))
    sets = [set(), {"Walk"}, {"Stationary"}, {"Cross", "Walk"}, {"Dance"}]
    assert matched_ids(program, pedestrian_trace(sets), synthetic_map(), 5, options) == {"walker"}
    standing = HEADER + "ego = new Pedestrian\n"
    assert matched_ids(standing, pedestrian_trace(sets), synthetic_map(), 5, options) == set()
    assert matched_ids(standing, pedestrian_trace([{"Stationary"}] * 5), synthetic_map(), 5, options) == {"walker"}


def test_any_behaviour_inside_a_behaviour():
    # "whatever it does for 2 steps, then it turns left"; a bare `do AnyBehavior()` could run the whole
    # window, so what follows it constrains nothing
    program = HEADER + (
        "behavior B():\n    do AnyBehavior() for 2 steps\n    do TurnLeftBehavior()\nego = new Car with behavior B()\n"
    )
    labels = ["FollowLane", "Brake", "TurnLeft", "TurnLeft", "TurnLeft"]
    assert "car2" in matched_ids(program, worked_trace(labels), worked_map(), 5)
    assert "car2" not in matched_ids(program, worked_trace(labels[:4] + ["FollowLane"]), worked_map(), 5)
    assert "car2" not in matched_ids(program, worked_trace(["FollowLane"] * 3 + ["TurnLeft"] * 2), worked_map(), 5)
    unbounded = program.replace(" for 2 steps", "")
    assert "car2" in matched_ids(unbounded, worked_trace(["FollowLane"] * 5), worked_map(), 5)


def test_any_behaviour_is_not_a_scenic_name():
    # the primitive must not shadow a behaviour of Scenic 3.1.1's libraries
    spec = importlib.util.find_spec("scenic")
    assert spec is not None and spec.origin is not None
    package = Path(spec.origin).parent
    for path in [*package.rglob("*.scenic"), *package.rglob("*.py")]:
        assert "AnyBehavior" not in path.read_text(encoding="utf-8", errors="replace"), path
    assert load_vocabulary().primitive("Any").admits_any


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('[A]\nany = true\nlabels = ["X"]\n', "takes no labels"),
        ("[A]\nany = 1\n", "any must be true or false"),
        ("[A]\nall = true\n", "only the keys"),
    ],
)
def test_bad_any_entries_are_user_errors(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(UserError, match=message):
        read_vocabulary(path)


def test_a_users_vocabulary_can_declare_its_own_any_primitive(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text("[Whatever]\nany = true\nends = false\n")
    primitive = load_vocabulary(path).primitive("Whatever")
    assert primitive.admits_any and not primitive.ends


@pytest.mark.parametrize("call", ["TurnLeftt()", "do FollowLaneBehaviour()"])
def test_a_behaviour_nobody_defines_is_an_error_at_its_line_and_column(call):
    """As Scenic's NameError: a name neither the program nor the vocabulary defines is refused, not
    matched as a primitive no label stands for."""
    body = (
        f"ego = new Car with behavior {call}\n"
        if not call.startswith("do")
        else (f"behavior Go():\n    {call}\nego = new Car with behavior Go()\n")
    )
    with pytest.raises(UserError, match=r"unknown behaviour \w+: the program does not define it") as caught:
        compile_scenario(HEADER + body)
    line = 2 if not call.startswith("do") else 3
    assert str(caught.value).startswith(f"<program>:{line}:")


def test_a_users_vocabulary_can_name_its_own_primitive(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[Overtake]\nlabels = ["Overtake"]\n')
    query = compile_scenario(
        HEADER + "ego = new Car with behavior OvertakeBehavior()\n", vocabulary=load_vocabulary(path)
    )
    assert query.vocabulary.primitive("Overtake").labels == {"Overtake"}
