"""Seed 000 §4.6 (Fig. 1 program, Table 2 trace, m = 5 -> Table 3) and the query examples of §2."""

import numpy as np
import pytest

from scenegrep.scenario import ScenarioOptions, load_scenario
from scenegrep.scenario.hfsm import BOTH, CAN_FALSE

from .worked_example import worked_map, worked_trace

FIG1 = "examples/queries/fig1_lane_change.scenic"
FL, LC, ST = "FollowLane", "LaneChange", "Stationary"


@pytest.fixture(scope="module")
def fig1():
    return load_scenario(FIG1)


def test_table3_guard_values_and_hfsm_outputs(fig1):
    """Table 3: distance, value of g = distance < Range(1, 15), and each HFSM's outputs per step."""
    result = fig1.match(worked_trace(), 5, road_map=worked_map())
    assert result.matched
    assert result.matches[0].correspondence == {"ego": "car2", "otherCar": "car1"}
    assert result.matches[0].starts.tolist() == [0]
    explainer = result.explainer
    assignment = {"ego": 1, "otherCar": 0}
    ego_steps = explainer.run("ego", assignment, 0, 5)
    other_steps = explainer.run("otherCar", assignment, 0, 5)
    automaton = explainer.search.automata["ego"]
    guard = [automaton.inputs(symbol).guards[0] for symbol, _, _ in ego_steps]
    assert guard == [CAN_FALSE, BOTH, BOTH, BOTH, BOTH]
    assert [outputs for _, outputs, _ in ego_steps] == [{FL}] + [{FL, LC}] * 4
    assert [outputs for _, outputs, _ in other_steps] == [{ST}] * 5
    states = result.trace.states
    distance = np.hypot(states.x[1::2] - states.x[0::2], states.y[1::2] - states.y[0::2])
    assert np.round(distance, 2).tolist() == [20.0, 14.0, 10.0, 6.03, 1.41]


def test_the_other_correspondence_fails_because_ego_cannot_be_stationary(fig1):
    result = fig1.match(worked_trace(), 5, road_map=worked_map())
    assert [m.correspondence for m in result.matches] == [{"ego": "car2", "otherCar": "car1"}]
    outcome = result.explainer.outcome
    assert set(outcome.unary["ego"]) == {1}  # car1 (row 0) only ever outputs Stationary


def test_witness_lists_each_step_with_labels_guards_and_states(fig1):
    lines = fig1.match(worked_trace(), 5, road_map=worked_map()).explain()
    assert lines[0].startswith("window frame 0")
    assert "ego = car2" in lines[0] and "otherCar = car1" in lines[0]
    step2 = lines[lines.index(next(line for line in lines if line.startswith("step 2"))) + 1]
    assert "label {LaneChange}" in step2 and "is true or false" in step2
    assert "HFSM outputs {FollowLane, LaneChange}" in step2 and "interrupt (line 13) > LaneChange" in step2


def test_section2_turn_left_trace_does_not_match(fig1):
    """§2: with ego labelled TL, FL, LC, TL the program cannot produce the ego's labels."""
    trace = worked_trace(["TurnLeft", FL, LC, "TurnLeft", FL])
    result = fig1.match(trace, 5, road_map=worked_map())
    assert not result.matched
    assert "TurnLeft" in result.why_not()


def test_section2_lane_change_trace_matches(fig1):
    """§2: FL, FL, LC, FL is an output of the program once the other car is near."""
    trace = worked_trace([FL, FL, LC, LC, FL])
    assert fig1.match(trace, 5, road_map=worked_map()).matched


def test_lane_change_before_the_guard_can_hold_does_not_match(fig1):
    """At 20 m the guard is false (Range(1, 15)), so a lane change at step 0 is impossible."""
    result = fig1.match(worked_trace([LC, LC, LC, LC, FL]), 5, road_map=worked_map())
    assert not result.matched
    assert "frame 0" in result.why_not()


def test_shorter_windows_slide(fig1):
    result = fig1.match(worked_trace(), 2, road_map=worked_map(), options=ScenarioOptions(find_all=True))
    # all four windows of 2 frames: the other car stays in view on the ego's lane
    assert result.matches[0].starts.tolist() == [0, 1, 2, 3]
