"""The online labeller (scenegrep.label.online) against the offline one on the whole trace.

Property: random traces on the synthetic map (cars and pedestrians weaving across lanes, through
the intersection and the crosswalk, stopping, reversing, with track breaks longer than
``max_gap_s``, or moving exactly on the decision boundaries) fed in random chunk sizes give every
observation the label set and the confidences (bit for bit) the offline labeller gives it, unless
the labeller declared a possible difference (:attr:`OnlineLabeller.warnings`); every frame is
handed out once, in order.
"""

from __future__ import annotations

from dataclasses import fields, replace

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.label import label_trace, load_config
from scenegrep.label.online import OnlineLabeller, reach
from scenegrep.label.tracks import Tracks
from scenegrep.model import LabelTrace, ObjectTable, StateTable, concatenate
from scenegrep.model.layers import UnknownLayers

from .tracks import DT, motion_heading, neighbour_map

ROAD_MAP = neighbour_map()
UNKNOWN_CROSSINGS = replace(ROAD_MAP, unknown_layers=frozenset({"crossing"}))


def _speed_bounds() -> list[float]:
    """Both ends of every speed ramp of the shipped thresholds (m/s), with their opposites."""
    config = load_config()
    bounds = {
        abs(v)
        for part in (config.vehicle, config.pedestrian)
        for f in fields(part)
        if f.name.endswith("_mps")
        for v in getattr(part, f.name)
    }
    return sorted(bounds | {-v for v in bounds})


SPEED_BOUNDS = _speed_bounds()
RIGHT_ANGLES = [0.0, np.pi / 2, np.pi, -np.pi / 2]
"""Headings along and exactly across the synthetic map's lanes (which run along y)."""


@st.composite
def _exact_track(draw, n: int) -> tuple[np.ndarray, ...]:
    """x, y, heading, vx, vy of a track on the decision boundaries: its own constant velocity
    (given, not derived) at a ramp's end along or across the lanes, on a lane boundary, facing
    along or exactly across the lanes."""
    speed, across = draw(st.sampled_from(SPEED_BOUNDS)), draw(st.booleans())
    vx, vy = np.full(n, speed if across else 0.0), np.full(n, 0.0 if across else speed)
    x = draw(st.sampled_from([-3.5, 0.0, 1.75, 3.5, 7.0])) + np.cumsum(vx * DT)
    y = draw(st.sampled_from([0.0, 49.0, 52.0, 59.5, 62.0, 99.0])) + np.cumsum(vy * DT)
    return x, y, np.full(n, draw(st.sampled_from(RIGHT_ANGLES))), vx, vy


@st.composite
def traces(draw) -> LabelTrace:
    """A trace of 1-4 objects, each seen from some frame on, with at most one long break; some
    objects move exactly on the labeller's decision boundaries (:func:`_exact_track`)."""
    n_frames = draw(st.integers(2, 90))
    frames, objects, xs, ys, headings, vxs, vys, kinds = [], [], [], [], [], [], [], []
    for k in range(draw(st.integers(1, 4))):
        first = draw(st.integers(0, n_frames - 1))
        seen = np.arange(first, draw(st.integers(first + 1, n_frames)))
        if draw(st.booleans()) and len(seen) > 4:
            cut = draw(st.integers(1, len(seen) - 2))
            seen = np.concatenate([seen[:cut], seen[cut:] + draw(st.integers(11, 20))])
            seen = seen[seen < n_frames]
        if draw(st.booleans()):
            x, y, heading, vx, vy = draw(_exact_track(len(seen)))
        else:
            steps = draw(st.lists(st.floats(-3.0, 3.0), min_size=len(seen), max_size=len(seen)))
            vx = np.repeat(draw(st.lists(st.floats(-2.0, 2.0), min_size=4, max_size=4)), -(-len(seen) // 4))
            x = draw(st.floats(-3.0, 7.0)) + np.cumsum(vx[: len(seen)] * DT)
            y = draw(st.floats(0.0, 190.0)) + np.cumsum(np.asarray(steps)) * DT * 4
            heading = motion_heading(x, y) if len(seen) > 1 else np.zeros(1)
            vx = vy = np.full(len(seen), np.nan)  # derived by the labeller
        if draw(st.booleans()):
            heading = heading + np.pi  # reversing: faces against its motion
        frames.append(seen)
        objects.append(np.full(len(seen), k))
        xs.append(x)
        ys.append(y)
        headings.append(heading)
        vxs.append(vx)
        vys.append(vy)
        kinds.append(draw(st.sampled_from(["car", "car", "pedestrian", "truck"])))
    n = sum(map(len, xs))
    states = StateTable.build(
        np.concatenate(frames),
        np.concatenate(objects),
        np.concatenate(xs),
        np.concatenate(ys),
        np.concatenate(headings),
        length=np.full(n, 4.5),
        width=np.full(n, 2.0),
        vx=np.concatenate(vxs),
        vy=np.concatenate(vys),
    )
    table = ObjectTable.build([f"o{k}" for k in range(len(kinds))], kinds)
    return LabelTrace.build("random", np.arange(n_frames), np.arange(n_frames) * DT, table, states)


def online(
    trace: LabelTrace,
    sizes: list[int],
    road_map=ROAD_MAP,
    choice: UnknownLayers | None = None,
    min_confidence: float | None = None,
) -> tuple[LabelTrace, OnlineLabeller]:
    """``trace`` pushed in chunks of ``sizes`` (cycled), then finished; the frames handed out."""
    choice = choice or UnknownLayers("permissive")
    labeller = OnlineLabeller(road_map, min_confidence=min_confidence, unknown_layers=choice)
    parts, start, k = [], 0, 0
    while start < trace.n_frames:
        stop = start + sizes[k % len(sizes)]
        parts.append(labeller.push(trace.slice_frames(start, stop)))
        start, k = stop, k + 1
    parts.append(labeller.finish())
    return concatenate([p for p in parts if p is not None]), labeller


def by_observation(trace: LabelTrace) -> dict[tuple[float, str], tuple[np.ndarray, np.ndarray]]:
    """(frame time, object id) -> (label set, confidences) of every observation."""
    ids = trace.objects.id[trace.states.object]
    times = trace.frame_time[trace.states.frame]
    labels = trace.behaviours
    return {
        (float(t), str(i)): (labels.member[row], labels.confidence[row])
        for row, (t, i) in enumerate(zip(times, ids, strict=True))
    }


@settings(max_examples=40, deadline=None, phases=(Phase.explicit, Phase.generate), derandomize=True)
@given(
    traces(),
    st.lists(st.integers(1, 7), min_size=1, max_size=5),
    st.booleans(),
    st.sampled_from([None, 0.5, 1.0]),
)
def test_online_labels_equal_offline_labels(trace, sizes, unknown, min_confidence):
    """Bit for bit, ties at the thresholds included (a confidence exactly at the minimum, a speed
    at a ramp's end, a heading exactly across its lane), unless the labeller declared a possible
    difference; on a map without a crosswalk layer, the permissive choice counts the decisions it
    affected once per observation, as offline (not once per relabelling of the kept history)."""
    road_map = UNKNOWN_CROSSINGS if unknown else ROAD_MAP
    offline_choice, online_choice = UnknownLayers("permissive"), UnknownLayers("permissive")
    offline = label_trace(trace, road_map, None, min_confidence, offline_choice).trace
    result, labeller = online(trace, sizes, road_map, online_choice, min_confidence)
    assert online_choice.decisions == offline_choice.decisions
    assert np.array_equal(result.frame_time, trace.frame_time)
    expected, got = by_observation(offline), by_observation(result)
    assert got.keys() == expected.keys()
    if labeller.warnings:
        return
    for key, (member, confidence) in expected.items():
        assert np.array_equal(got[key][0], member), key
        assert np.array_equal(got[key][1], confidence, equal_nan=True), key


def test_frames_wait_for_the_lookahead():
    """A car seen at every frame: frame f is handed out once frame f + H has arrived, not before."""
    n = 80
    y = np.arange(n) * 1.0
    states = StateTable.build(np.arange(n), np.zeros(n, int), np.full(n, 1.75), y, np.zeros(n))
    trace = LabelTrace.build("car", np.arange(n), np.arange(n) * DT, ObjectTable.build(["c"], ["car"]), states)
    depth = reach(load_config(), Tracks.of(trace, 1.0), knows_intersections=True)
    assert depth == 35  # 10 Hz, smoothing 1 s (h = 5), turn margin 3 s: 5 + 30
    labeller = OnlineLabeller(ROAD_MAP)
    handed = [labeller.push(trace.slice_frames(f, f + 1)) for f in range(n)]
    counts = [0 if part is None else part.n_frames for part in handed]
    assert sum(counts[:depth]) == 0
    assert counts[depth:] == [1] * (n - depth)
    assert labeller.finish().n_frames == depth
    assert "35 observations" in labeller.delay()


def test_a_closed_track_is_final_after_max_gap():
    """A track that stops being observed is final max_gap_s later, without waiting H positions."""
    n = 30
    states = StateTable.build(np.arange(5), np.zeros(5, int), np.full(5, 1.75), np.arange(5.0), np.zeros(5))
    trace = LabelTrace.build("car", np.arange(n), np.arange(n) * DT, ObjectTable.build(["c"], ["car"]), states)
    labeller = OnlineLabeller(ROAD_MAP)
    counts = [getattr(labeller.push(trace.slice_frames(f, f + 1)), "n_frames", 0) for f in range(n)]
    assert sum(counts[:14]) == 0  # last observation at 0.4 s; closed once 1.4 s has arrived
    assert counts[14] == 15


def test_without_a_choice_the_unknown_crosswalk_layer_is_refused_as_offline():
    """A pedestrian walking along a lane on a map without a crosswalk layer: online, as offline, an
    error naming the layer and the option once the frames are handed out; a car alone is no error."""
    n = 40
    y = np.arange(n) * 0.15
    walker = StateTable.build(np.arange(n), np.zeros(n, int), np.full(n, 1.75), y, np.zeros(n))
    table = ObjectTable.build(["p"], ["pedestrian"])
    trace = LabelTrace.build("walker", np.arange(n), np.arange(n) * DT, table, walker)
    with pytest.raises(UserError, match="crossing layer.*--unknown-layers") as offline:
        label_trace(trace, UNKNOWN_CROSSINGS)
    with pytest.raises(UserError) as got:
        online(trace, [5], UNKNOWN_CROSSINGS, UnknownLayers())
    assert got.value.message.split("(")[0] == offline.value.message.split("(")[0]
    car = replace(trace, objects=ObjectTable.build(["c"], ["car"]))
    assert online(car, [5], UNKNOWN_CROSSINGS, UnknownLayers())[0].n_frames == n


@pytest.mark.parametrize("interval", [0.1, 0.5])
def test_a_changed_interval_is_declared(interval):
    """Frames at 10 Hz, then at 2 Hz: the pinned 0.1 s interval no longer counts the windows
    the history's own median would, and the labeller says so."""
    times = np.concatenate([np.arange(40) * 0.1, 4.0 + np.arange(1, 40) * interval])
    n = len(times)
    states = StateTable.build(np.arange(n), np.zeros(n, int), np.full(n, 1.75), times * 5, np.zeros(n))
    trace = LabelTrace.build("car", np.arange(n), times, ObjectTable.build(["c"], ["car"]), states)
    _, labeller = online(trace, [3])
    assert bool(labeller.warnings) == (interval != 0.1)


REAL = {
    "av2": "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede",
    "nuscenes": "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl",
}


@pytest.mark.real_data
@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(REAL))
def test_real_logs_frame_by_frame(real_data, name):
    """AV2 7fab2350 and nuScenes scene-0061 fed one frame at a time: every observation's label set is
    the offline one, the permissive choice for the crosswalks nuScenes maps do not publish counts as
    many decisions (some), and ``stationary_vehicle.scenic --all`` over 10-frame windows of the first
    60 frames finds exactly the offline windows and correspondences."""
    from scenegrep import readers
    from scenegrep.dataset.queries import scenario_rows
    from scenegrep.scenario import ScenarioOptions, load_scenario, load_vocabulary
    from scenegrep.scenario.online import OnlineScenario

    trace = readers.read_trace(real_data / REAL[name])
    trace = replace(trace.slice_frames(0, 60), behaviours=None)
    road_map = readers.read_map(trace.map_source)
    choice, offline_choice, online_choice = (UnknownLayers("permissive") for _ in range(3))
    offline = label_trace(trace, road_map, unknown_layers=offline_choice).trace
    labeller = OnlineLabeller(road_map, unknown_layers=online_choice)
    query = load_scenario("examples/queries/real/stationary_vehicle.scenic", load_vocabulary(None), None)
    options = ScenarioOptions(find_all=True, unknown_layers=choice)
    matcher = OnlineScenario(query, 10, road_map, options)
    parts, found = [], []
    for ready in [labeller.push(trace.slice_frames(f, f + 1)) for f in range(60)] + [labeller.finish()]:
        if ready is not None:
            parts.append(ready)
            found += [row for result in matcher.push(ready) for row in scenario_rows(result, True, False)]
    expected, got = by_observation(offline), by_observation(concatenate(parts))
    assert got.keys() == expected.keys()
    assert all(np.array_equal(got[key][0], member) for key, (member, _) in expected.items())
    assert online_choice.decisions == offline_choice.decisions
    assert (offline_choice.decisions["crossing"] > 0) == (name == "nuscenes")
    rows = scenario_rows(query.match(offline, 10, road_map, options), True, False)
    key = ("start_frame", "end_frame", "correspondence")
    assert len(rows) > 0
    assert sorted(tuple(r[k] for k in key) for r in found) == sorted(tuple(r[k] for k in key) for r in rows)
