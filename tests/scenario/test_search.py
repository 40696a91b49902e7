"""The correspondence search and sliding windows against a brute-force Algorithm 1 + 2.

The reference enumerates every injective correspondence and every window start,
checks the initial scene with the scene query at that frame, and runs ValidStep
literally (sets of HFSM configurations, stepped frame by frame with guard values
computed here in closed form: ``d < Range(1, 15)`` can hold iff d < 15 and can
fail iff d >= 1).
"""

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.scenario import ScenarioOptions, load_scenario
from scenegrep.scenario.hfsm import CAN_FALSE, CAN_TRUE, StepInputs
from scenegrep.scene.match import SceneOptions

from .worked_example import worked_map

FIG1 = load_scenario("examples/queries/fig1_lane_change.scenic")
LABELS = ["FollowLane", "LaneChange", "Stationary", "TurnLeft"]
MAP = worked_map()


@st.composite
def traces(draw):
    n_objects = draw(st.integers(2, 4))
    n_frames = draw(st.integers(1, 8))
    rows = []
    for frame in range(n_frames):
        for obj in range(n_objects):
            if draw(st.integers(0, 9)) == 0:
                continue  # absent in this frame
            y = draw(st.sampled_from([-30.0, -20.0, -12.0, -5.0, 0.0, 6.0, 14.0]))
            x = draw(st.sampled_from([0.0, 0.0, -0.5]))
            label = draw(st.sampled_from(LABELS[:3] if draw(st.booleans()) else LABELS))
            rows.append((frame, obj, x, y + obj * 0.01, label))
    if not rows:
        rows.append((0, 0, 0.0, 0.0, "Stationary"))
    frame, obj, x, y, label = zip(*rows)
    states = StateTable.build(
        frame=frame, object=obj, x=x, y=y, heading=np.zeros(len(rows)),
        length=np.full(len(rows), 4.5), width=np.full(len(rows), 2.0),
    )  # fmt: skip
    objects = ObjectTable.build([f"car{k}" for k in range(n_objects)], ["car"] * n_objects)
    behaviours = BehaviourLabels.from_sets([{name} for name in label])
    return LabelTrace.build(
        "random", np.arange(n_frames), np.arange(n_frames) * 0.1, objects, states, behaviours=behaviours
    )


def guard_value(trace, frame, ego, other):
    states = trace.states
    a = np.flatnonzero((states.frame == frame) & (states.object == ego))
    b = np.flatnonzero((states.frame == frame) & (states.object == other))
    if not len(a) or not len(b):
        return CAN_TRUE | CAN_FALSE
    d = np.hypot(states.x[a[0]] - states.x[b[0]], states.y[a[0]] - states.y[b[0]])
    return (CAN_TRUE if d < 15 else 0) | (CAN_FALSE if d >= 1 else 0)


def label_at(trace, frame, obj):
    rows = np.flatnonzero((trace.states.frame == frame) & (trace.states.object == obj))
    return set(trace.behaviours.sets()[rows[0]]) if len(rows) else set()


def admitted(label, observed):
    return bool(FIG1.vocabulary.primitive(label).labels & observed)


def brute_force(trace, m):
    """{(correspondence items, start)} of every matching window, by Algorithms 1 and 2."""
    found = set()
    ids = trace.objects.id
    for ego, other in itertools.permutations(range(trace.n_objects), 2):
        correspondence = {"ego": str(ids[ego]), "otherCar": str(ids[other])}
        scene = FIG1.scene.match(trace, MAP, SceneOptions(correspondence=correspondence)).matched
        for start in range(trace.n_frames - m + 1):
            if not scene[start]:
                continue
            current = {"ego": {None}, "otherCar": {None}}
            alive = True
            for t in range(start, start + m):
                inputs = StepInputs((guard_value(trace, t, ego, other),), 0.1)
                for name, row in (("ego", ego), ("otherCar", other)):
                    observed = label_at(trace, t, row)
                    hfsm = FIG1.hfsms[name]
                    current[name] = {
                        o.config for c in current[name] for o in hfsm.step(c, inputs) if admitted(o.label, observed)
                    }
                    alive &= bool(current[name])
                if not alive:
                    break
            if alive:
                found.add((tuple(sorted(correspondence.items())), start))
    return found


@settings(max_examples=150, deadline=None)
@given(traces(), st.integers(1, 5))
def test_every_correspondence_and_window_agrees_with_brute_force(trace, m):
    result = FIG1.match(trace, m, road_map=MAP, options=ScenarioOptions(find_all=True))
    fast = {(tuple(sorted(match.correspondence.items())), int(s)) for match in result.matches for s in match.starts}
    assert fast == brute_force(trace, m)


@settings(max_examples=100, deadline=None)
@given(traces(), st.integers(1, 5))
def test_first_match_exists_iff_brute_force_finds_one(trace, m):
    result = FIG1.match(trace, m, road_map=MAP)
    reference = brute_force(trace, m)
    assert result.matched == bool(reference)
    if result.matched:
        match = result.matches[0]
        assert (tuple(sorted(match.correspondence.items())), int(match.starts[0])) in reference
    else:
        assert result.why_not()
