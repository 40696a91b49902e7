"""Turn and lane-change sides (issue 16): on random vehicle tracks, the labeller's TurnLeft/TurnRight
are the counter-clockwise and clockwise halves of one heading change, and LaneChangeLeft/Right are
moves to the left and to the right of the lane's direction, against a brute-force reference written
here with plain loops over each track; and, through the scenario vocabulary, Turn admits exactly the
frames TurnLeft or TurnRight admits, LaneChange exactly those LaneChangeLeft or LaneChangeRight admits.

Conventions (README, "Semantics choices"): headings are radians, 0 = +y, counter-clockwise positive,
so a left turn increases the heading; on the synthetic map every lane a northbound car can be in
outside the intersection runs north, so the left of its direction is -x.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.label import label_trace, load_config
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.scenario.vocabulary import load_vocabulary
from tests.label.tracks import DT, neighbour_map

MAP = neighbour_map()
CONFIG = load_config()
VOCABULARY = load_vocabulary()
INTERSECTION = (-3.5, 50.0, 7.0, 53.5)  # x1 of tests/model/maps.py, the map's one intersection


def wrap(angle: float) -> float:
    """An angle in (-pi, pi]."""
    wrapped = math.remainder(angle, 2 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


@st.composite
def vehicle_tracks(draw, northbound: bool = False):
    """Frames, x, y and box headings of one vehicle: piecewise-constant speed and yaw rate, some
    frames missing (a gap longer than a second splits the track)."""
    n = draw(st.integers(2, 120))
    start = draw(st.integers(0, 20))
    x, y = draw(st.floats(0.5, 6.5)), draw(st.floats(20.0, 70.0))
    heading = draw(st.floats(-0.3, 0.3)) if northbound else draw(st.floats(-math.pi, math.pi))
    pieces = draw(
        st.lists(st.tuples(st.floats(0.0, 15.0), st.floats(-0.8, 0.8), st.floats(-1.5, 1.5)), min_size=1, max_size=4)
    )
    xs, ys, hs = [], [], []
    for k in range(n):
        speed, yaw_rate, lateral = pieces[k * len(pieces) // n]
        if northbound:
            yaw_rate, lateral = 0.0, lateral * 0.5
        xs.append(x)
        ys.append(y)
        hs.append(wrap(heading))
        x += (-math.sin(heading) * speed - math.cos(heading) * lateral) * DT
        y += (math.cos(heading) * speed - math.sin(heading) * lateral) * DT
        heading += yaw_rate * DT
    keep = np.ones(n, dtype=bool)
    if draw(st.booleans()):
        first = draw(st.integers(0, n - 1))
        keep[first : first + draw(st.integers(1, 15))] = False
        keep[0] = True
    frames = start + np.arange(n)
    return frames[keep], np.array(xs)[keep], np.array(ys)[keep], np.array(hs)[keep]


@st.composite
def traces(draw, northbound: bool = False):
    tracks = draw(st.lists(vehicle_tracks(northbound), min_size=1, max_size=3))
    frame = np.concatenate([t[0] for t in tracks])
    obj = np.concatenate([np.full(len(t[0]), k) for k, t in enumerate(tracks)])
    n = len(frame)
    states = StateTable.build(
        frame=frame, object=obj, x=np.concatenate([t[1] for t in tracks]), y=np.concatenate([t[2] for t in tracks]),
        heading=np.concatenate([t[3] for t in tracks]), length=np.full(n, 4.5), width=np.full(n, 2.0),
    )  # fmt: skip
    n_frames = int(frame.max()) + 1
    objects = ObjectTable.build([f"v{k}" for k in range(len(tracks))], ["car"] * len(tracks))
    return LabelTrace.build("random", np.arange(n_frames), np.arange(n_frames) * DT, objects, states)


# ---------------------------------------------------------------- the brute-force reference
def segments(trace: LabelTrace) -> list[list[int]]:
    """Per object, its state rows in time order, cut where consecutive observations are more than
    [tracks].max_gap_s apart."""
    found = []
    for obj in range(trace.n_objects):
        rows = sorted(np.flatnonzero(trace.states.object == obj).tolist(), key=lambda r: trace.states.frame[r])
        current: list[int] = []
        for row in rows:
            if (
                current
                and trace.frame_time[trace.states.frame[row]] - trace.frame_time[trace.states.frame[current[-1]]]
                > CONFIG.tracks.max_gap_s
            ):
                found.append(current)
                current = []
            current.append(row)
        found.append(current)
    return [s for s in found if s]


def interval(trace: LabelTrace, parts: list[list[int]]) -> float:
    steps = [
        trace.frame_time[trace.states.frame[b]] - trace.frame_time[trace.states.frame[a]]
        for part in parts
        for a, b in zip(part, part[1:])
    ]
    return float(np.median(steps)) if steps else 0.1


def frames(seconds: float, step: float) -> int:
    return max(1, round(seconds / step))


def centred_mean(values: list[float], half: int) -> list[float]:
    out = []
    for i in range(len(values)):
        window = [v for v in values[max(0, i - half) : i + half + 1] if not math.isnan(v)]
        out.append(sum(window) / len(window) if window else math.nan)
    return out


def ramp(value: float, bounds: tuple[float, float]) -> float:
    low, high = bounds
    return 0.0 if math.isnan(value) else min(1.0, max(0.0, (value - low) / (high - low)))


def reference_turn(trace: LabelTrace, road_map) -> np.ndarray:
    """Per state row, the signed heading change (rad, counter-clockwise positive) the turn rule reads."""
    parts = segments(trace)
    step = interval(trace, parts)
    c = CONFIG.vehicle
    out = np.zeros(len(trace.states))
    for part in parts:
        raw = [float(trace.states.heading[r]) for r in part]
        unwrapped = [raw[0]]
        for a, b in zip(raw, raw[1:]):
            unwrapped.append(unwrapped[-1] + wrap(b - a))
        smooth = centred_mean(unwrapped, max(1, frames(CONFIG.tracks.smooth_s, step) // 2))
        half = max(1, frames(c.turn_window_s, step) // 2)
        margin = max(1, frames(c.turn_intersection_margin_s, step))
        x0, y0, x1, y1 = INTERSECTION
        inside = [x0 <= trace.states.x[r] <= x1 and y0 <= trace.states.y[r] <= y1 for r in part]
        for i, row in enumerate(part):
            change = smooth[min(i + half, len(part) - 1)] - smooth[max(i - half, 0)]
            near = any(inside[max(0, i - margin) : i + margin + 1])
            out[row] = change if road_map is None or near else 0.0
    return out


def reference_leftward_speed(trace: LabelTrace) -> np.ndarray:
    """Per state row, the smoothed speed towards -x (m/s): central differences of positions inside
    a segment, one-sided at its ends, averaged over the centred smoothing window."""
    parts = segments(trace)
    step = interval(trace, parts)
    out = np.full(len(trace.states), np.nan)
    for part in parts:
        t = [trace.frame_time[trace.states.frame[r]] for r in part]
        x = [float(trace.states.x[r]) for r in part]
        vx = []
        for i in range(len(part)):
            a, b = max(0, i - 1), min(len(part) - 1, i + 1)
            vx.append((x[b] - x[a]) / (t[b] - t[a]) if t[b] > t[a] else math.nan)
        for row, value in zip(part, centred_mean(vx, max(1, frames(CONFIG.tracks.smooth_s, step) // 2))):
            out[row] = -value
    return out


def confidence(trace: LabelTrace, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Membership and confidence (NaN where not a member) of one label, per state row."""
    labels = trace.behaviours
    k = labels.vocabulary.index(name)
    return labels.member[:, k], labels.confidence[:, k]


def admitted(trace: LabelTrace, primitive: str) -> np.ndarray:
    """Per state row, whether its label set admits the primitive (through the shipped vocabulary)."""
    labels = VOCABULARY.primitive(primitive).labels
    return np.array([bool(labels & s) for s in trace.behaviours.sets()])


# ---------------------------------------------------------------- the properties
@settings(max_examples=150, deadline=None)
@given(traces(), st.booleans())
def test_turn_sides_are_the_signed_halves_of_one_heading_change(trace, with_map):
    road_map = MAP if with_map else None
    labelled = label_trace(trace, road_map).trace
    change = reference_turn(trace, road_map)
    bounds, minimum = CONFIG.vehicle.turn_heading_change_rad, CONFIG.labels.min_confidence
    for name, sign in (("TurnLeft", 1.0), ("TurnRight", -1.0)):
        member, score = confidence(labelled, name)
        expected = np.array([ramp(sign * c, bounds) for c in change])
        np.testing.assert_allclose(score[member], expected[member], atol=1e-9)
        assert (expected[~member] < minimum).all()
    left, right = confidence(labelled, "TurnLeft")[0], confidence(labelled, "TurnRight")[0]
    assert not (left & right).any()
    assert (change[left] > 0).all() and (change[right] < 0).all()
    # the unsided turn, ramp(|change|), is exactly one of its sides' confidences
    unsided = np.array([ramp(abs(c), bounds) for c in change])
    halves = np.maximum([ramp(c, bounds) for c in change], [ramp(-c, bounds) for c in change])
    np.testing.assert_array_equal(unsided, halves)
    np.testing.assert_array_equal(
        admitted(labelled, "Turn"), admitted(labelled, "TurnLeft") | admitted(labelled, "TurnRight")
    )


@settings(max_examples=150, deadline=None)
@given(traces(northbound=True))
def test_lane_change_sides_follow_the_lateral_motion(trace):
    labelled = label_trace(trace, MAP).trace
    leftward = reference_leftward_speed(trace)
    left, right = confidence(labelled, "LaneChangeLeft")[0], confidence(labelled, "LaneChangeRight")[0]
    assert not (left & right).any()
    # a lane change is read while moving across the lane by at least the event ramp's start
    low = CONFIG.vehicle.lane_change_event_lateral_mps[0]
    assert (leftward[left] >= low - 1e-9).all() and (leftward[right] <= -low + 1e-9).all()
    x0, y0, x1, y1 = INTERSECTION
    inside = (trace.states.x >= x0) & (trace.states.x <= x1) & (trace.states.y >= y0) & (trace.states.y <= y1)
    assert not (inside & (left | right)).any()
    np.testing.assert_array_equal(
        admitted(labelled, "LaneChange"), admitted(labelled, "LaneChangeLeft") | admitted(labelled, "LaneChangeRight")
    )


def test_the_labeller_names_no_unsided_turn_or_lane_change():
    from scenegrep.label import VOCABULARY as LABELS

    assert {"TurnLeft", "TurnRight", "LaneChangeLeft", "LaneChangeRight"} <= set(LABELS)
    assert not {"Turn", "LaneChange"} & set(LABELS)


def test_a_car_overtaking_on_the_opposing_lane_changes_lanes_to_its_left():
    # northbound at 10 m/s in n1 (x 1.75), moving 3.5 m left into the southbound s1 (x -1.75) over 4 s:
    # the sides are the car's own, not those of the lane it is in (s1 runs south: its left is +x)
    t = np.arange(0, 8.0 + DT / 2, DT)
    x = np.where(t < 2, 1.75, np.where(t > 6, -1.75, 1.75 - 3.5 * (t - 2) / 4))
    y = 5.0 + 10.0 * t
    n = len(t)
    states = StateTable.build(
        frame=np.arange(n), object=np.zeros(n, dtype=np.int64), x=x, y=y, heading=np.zeros(n),
        length=np.full(n, 4.5), width=np.full(n, 2.0),
    )  # fmt: skip
    trace = LabelTrace.build("overtake", np.arange(n), t, ObjectTable.build(["car"], ["car"]), states)
    labelled = label_trace(trace, MAP).trace
    left, right = confidence(labelled, "LaneChangeLeft")[0], confidence(labelled, "LaneChangeRight")[0]
    in_s1 = x < 0
    assert left[in_s1 & (t < 6)].any() and left[~in_s1 & (t > 2.5)].any()
    assert not right.any()
