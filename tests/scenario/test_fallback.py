"""When an HFSM's lazy DFA is over its state budget, the search simulates configuration sets
(:mod:`scenegrep.scenario.simulate`) and gives the same answers.

* random nested behaviours (the generators of test_hfsm_semantics), several rows of random symbols:
  the simulation's reach equals windows.reach over the DFA's table wherever the table fits;
* random traces (test_search's generator) and the sample traces: a query whose budget forces the
  fallback (2 states: the dead and the initial state) finds the same correspondences and windows;
* seed 000's s4 query on the real AV2 log adcf7d18 and the Waymo scenario, whose ego DFA is over
  the default budget, answers (it was "too many reachable state sets").
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from hypothesis import event, given, settings
from hypothesis import strategies as st

from scenegrep import readers
from scenegrep.label import label_trace
from scenegrep.scenario import ScenarioOptions, load_scenario
from scenegrep.scenario.automaton import Automaton, OverBudget, encode
from scenegrep.scenario.hfsm import BOTH, CAN_FALSE, CAN_TRUE
from scenegrep.scenario.simulate import simulate_reach
from scenegrep.scenario.windows import table_reach
from scenegrep.scene import Tolerance

from scenegrep.model.layers import UnknownLayers
from .test_hfsm_semantics import N_GUARDS, PERIOD, STATE_BUDGET, behaviours, to_hfsm
from .test_search import MAP, traces

FORCED = 2
"""A state budget that sends every HFSM with a behaviour to the fallback."""

S4 = "examples/queries/s4_yield_right_turn.scenic"
AV2 = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"
WAYMO = "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl"


@settings(max_examples=200, deadline=None)
@given(data=st.data(), tree=behaviours(), k=st.integers(1, 3), n=st.integers(1, 8), cap=st.integers(1, 6))
def test_the_simulation_equals_the_dfa_on_random_nested_behaviours(data, tree, k, n, cap):
    hfsm = to_hfsm(tree)
    n_outputs = len(hfsm.outputs())
    labels = data.draw(st.lists(st.integers(0, (1 << n_outputs) - 1), min_size=k * n, max_size=k * n), "labels")
    codes = [
        np.array(data.draw(st.lists(st.sampled_from((CAN_TRUE, CAN_FALSE, BOTH)), min_size=k * n, max_size=k * n)))
        for _ in hfsm.guards
    ]
    symbols = encode(np.array(labels), codes, n_outputs).reshape(k, n)
    automaton = Automaton(hfsm, N_GUARDS, PERIOD, STATE_BUDGET)
    try:
        expected = table_reach(automaton, symbols, cap)
    except OverBudget:
        event("the DFA is over its budget")
        return
    assert simulate_reach(automaton, symbols, cap).tolist() == expected.tolist()


def _answers(query, trace, m, road_map=None, tolerance=None):
    """Every answer; the layers a map does not publish (the Waymo pickle's shoulders, which the cars'
    default container reads) are taken as anywhere."""
    options = ScenarioOptions(tolerance or Tolerance(), find_all=True, unknown_layers=UnknownLayers("permissive"))
    result = query.match(trace, m, road_map=road_map, options=options)
    return sorted((sorted(match.correspondence.items()), match.starts.tolist()) for match in result.matches)


def _forced(path: str):
    query = load_scenario(path)
    query.state_budget = FORCED
    return query


FIG1 = load_scenario("examples/queries/fig1_lane_change.scenic")
FIG1_FORCED = _forced("examples/queries/fig1_lane_change.scenic")


@settings(max_examples=100, deadline=None)
@given(traces(), st.integers(1, 5))
def test_the_forced_fallback_finds_what_the_dfa_finds_on_random_traces(trace, m):
    assert _answers(FIG1_FORCED, trace, m, MAP) == _answers(FIG1, trace, m, MAP)


@pytest.mark.parametrize("name", ["s1_lane_change_stationary_car", "s4_yield_right_turn"])
def test_the_forced_fallback_finds_what_the_dfa_finds_on_the_sample(name):
    path = f"examples/queries/{name}.scenic"
    query, forced = load_scenario(path), _forced(path)
    found = 0
    for trace in readers.read_traces("examples/sample"):
        if trace.name.startswith(name):
            expected = _answers(query, trace, trace.n_frames // 2)
            assert _answers(forced, trace, trace.n_frames // 2) == expected
            found += len(expected)
    assert found and all(a.over_budget for a in forced._automata.values() if a.hfsm.root is not None)


@pytest.mark.parametrize(
    ("source", "window", "expected"),
    [
        (AV2, "2s", [("ego", "ego"), ("otherCar", "41269c43-9935-4093-80af-98df27071e5c")]),
        (WAYMO, "2s", None),
        (AV2, "4s", None),
        (WAYMO, "4s", None),
    ],
)
def test_s4_answers_on_real_data_over_the_default_budget(real_data, source, window, expected):
    trace = label_trace(next(iter(readers.read_traces(real_data / source)))).trace
    query = load_scenario(S4)
    began = time.perf_counter()
    answers = _answers(query, trace, window, tolerance=Tolerance(0.5, 0.2))
    assert time.perf_counter() - began < 20
    assert any(automaton.over_budget for automaton in query._automata.values())
    assert [a for a, _ in answers][:1] == ([expected] if expected else [])


def test_step_tables_over_their_cell_budget_fall_back_too(monkeypatch):
    """A DFA within its state budget whose doubling tables would exceed windows.MAX_CELLS (many
    candidates, long traces) is simulated as well, with the same answers."""
    query = load_scenario("examples/queries/s1_lane_change_stationary_car.scenic")
    traces = [t for t in readers.read_traces("examples/sample") if t.name.startswith("s1_")]
    expected = [_answers(query, trace, trace.n_frames // 2) for trace in traces]
    simulated = []

    def counted(*args):
        simulated.append(args)
        return simulate_reach(*args)

    monkeypatch.setattr("scenegrep.scenario.windows.MAX_CELLS", 1)
    monkeypatch.setattr("scenegrep.scenario.search.simulate_reach", counted)
    fresh = load_scenario("examples/queries/s1_lane_change_stationary_car.scenic")
    assert [_answers(fresh, trace, trace.n_frames // 2) for trace in traces] == expected
    assert any(expected) and simulated and not any(a.over_budget for a in fresh._automata.values())
