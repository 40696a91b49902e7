"""Agreement of derived labels with a simulation's running behaviour.

The slow test runs seed 000's Fig. 1 program and scenario 1 in Scenic's Newtonian simulator and
asks issue 5's acceptance: the labeller recovers FollowLane, LaneChange and Stationary on at
least 90 % of frames (benchmarks/label_agreement.py reports the full table over every program).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from scenegrep.label import label_trace
from scenegrep.label.agreement import Agreement
from scenegrep.model import BehaviourLabels
from scenegrep.readers import read_map
from tests.label.tracks import neighbour_map, trace_of

REPO = Path(__file__).resolve().parents[2]


def with_truth(trace, names):
    return replace(trace, behaviours=BehaviourLabels.from_sets([{n} for n in names]))


def test_recovery_counts_sets_top_labels_and_disagreements():
    t = np.arange(8) * 0.1
    trace = trace_of(("car", np.full(8, 1.75), 10.0 + 10.0 * t, None))
    truth = with_truth(trace, ["LaneChange"] * 4 + ["FollowLane"] * 4)
    labelled = replace(
        trace,
        behaviours=BehaviourLabels.from_sets(
            [{"LaneChangeLeft": 0.9, "FollowLane": 0.3}] * 2
            + [{"FollowLane": 0.8, "LaneChangeRight": 0.4}]
            + [{"FollowLane": 0.8}]
            + [{"FollowLane": 1.0}] * 3
            + [{"Stationary": 0.6}]
        ),
    )
    agreement = Agreement()
    agreement.add(truth, labelled)
    change, follow = agreement.truths["LaneChange"], agreement.truths["FollowLane"]
    assert (change.observations, change.recovered, change.top, change.set_size) == (4, 3, 2, 7)
    assert (follow.recovered, follow.top) == (3, 3) and follow.missed_as == {"Stationary": 1}
    assert change.missed_as == {"FollowLane": 1} and agreement.recovered_share("LaneChange") == 0.75
    assert "LaneChange" in agreement.table()


def test_the_labeller_agrees_with_itself_as_truth():
    t = np.arange(61) * 0.1
    trace = trace_of(("car", np.full(61, 1.75), 5.0 + 10.0 * t, None))
    labelled = label_trace(trace, neighbour_map()).trace
    agreement = Agreement()
    agreement.add(with_truth(trace, ["FollowLane"] * 61), labelled)
    assert agreement.recovered_share("FollowLane") == 1.0


@pytest.mark.slow
@pytest.mark.real_data
def test_simulated_running_behaviours_are_recovered(maps_dir):
    from scenegrep.synth.simulate import simulate_runs

    road_map = read_map(maps_dir / "Town06.xodr")
    agreement = Agreement()
    for name in ("fig1_lane_change", "s1_lane_change_stationary_car"):
        program = REPO / "examples" / "scenarios" / f"{name}.scenic"
        for truth in simulate_runs(program, map_path=maps_dir / "Town06.xodr", runs=3, steps=150, seed=7):
            agreement.add(truth, label_trace(replace(truth, behaviours=None), road_map).trace)
    for behaviour in ("FollowLane", "LaneChange", "Stationary"):
        assert agreement.recovered_share(behaviour) >= 0.9, agreement.table()
    assert agreement.truths["LaneChange"].observations >= 40
