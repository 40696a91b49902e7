"""The online labeller (scenegrep.label.online) against the offline one on the whole trace.

Property: random traces on the synthetic map (cars and pedestrians weaving across lanes, through
the intersection and the crosswalk, stopping, reversing, with track breaks longer than
``max_gap_s``) fed in random chunk sizes give every observation the label set the offline
labeller gives it, and confidences equal up to rounding, unless the labeller declared a possible
difference (:attr:`OnlineLabeller.warnings`); every frame is handed out once, in order.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import Phase, given, settings
from hypothesis import strategies as st

from scenegrep.label import label_trace, load_config
from scenegrep.label.online import OnlineLabeller, reach
from scenegrep.label.tracks import Tracks
from scenegrep.model import LabelTrace, ObjectTable, StateTable, concatenate
from scenegrep.model.layers import UnknownLayers

from .tracks import DT, motion_heading, neighbour_map

ROAD_MAP = neighbour_map()


@st.composite
def traces(draw) -> LabelTrace:
    """A trace of 1-4 objects, each seen from some frame on, with at most one long break."""
    n_frames = draw(st.integers(2, 90))
    frames, objects, xs, ys, headings, kinds = [], [], [], [], [], []
    for k in range(draw(st.integers(1, 4))):
        first = draw(st.integers(0, n_frames - 1))
        seen = np.arange(first, draw(st.integers(first + 1, n_frames)))
        if draw(st.booleans()) and len(seen) > 4:
            cut = draw(st.integers(1, len(seen) - 2))
            seen = np.concatenate([seen[:cut], seen[cut:] + draw(st.integers(11, 20))])
            seen = seen[seen < n_frames]
        steps = draw(st.lists(st.floats(-3.0, 3.0), min_size=len(seen), max_size=len(seen)))
        vx = np.repeat(draw(st.lists(st.floats(-2.0, 2.0), min_size=4, max_size=4)), -(-len(seen) // 4))[: len(seen)]
        x = draw(st.floats(-3.0, 7.0)) + np.cumsum(vx * DT)
        y = draw(st.floats(0.0, 190.0)) + np.cumsum(np.asarray(steps)) * DT * 4
        heading = motion_heading(x, y) if len(seen) > 1 else np.zeros(1)
        if draw(st.booleans()):
            heading = heading + np.pi  # reversing: faces against its motion
        frames.append(seen)
        objects.append(np.full(len(seen), k))
        xs.append(x)
        ys.append(y)
        headings.append(heading)
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
    )
    table = ObjectTable.build([f"o{k}" for k in range(len(kinds))], kinds)
    return LabelTrace.build("random", np.arange(n_frames), np.arange(n_frames) * DT, table, states)


def online(trace: LabelTrace, sizes: list[int]) -> tuple[LabelTrace, OnlineLabeller]:
    """``trace`` pushed in chunks of ``sizes`` (cycled), then finished; the frames handed out."""
    labeller = OnlineLabeller(ROAD_MAP, unknown_layers=UnknownLayers("permissive"))
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
@given(traces(), st.lists(st.integers(1, 7), min_size=1, max_size=5))
def test_online_labels_equal_offline_labels(trace, sizes):
    offline = label_trace(trace, ROAD_MAP, unknown_layers=UnknownLayers("permissive")).trace
    result, labeller = online(trace, sizes)
    assert np.array_equal(result.frame_time, trace.frame_time)
    expected, got = by_observation(offline), by_observation(result)
    assert got.keys() == expected.keys()
    differ = [key for key, (member, _) in expected.items() if not np.array_equal(got[key][0], member)]
    assert not differ or labeller.warnings, differ  # never silently different
    if not labeller.warnings:
        for key, (_, confidence) in expected.items():
            np.testing.assert_allclose(got[key][1], confidence, rtol=0, atol=1e-9, err_msg=str(key))


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
    the offline one, and ``stationary_vehicle.scenic --all`` over 10-frame windows of the first 60
    frames finds exactly the offline windows and correspondences."""
    from dataclasses import replace

    from scenegrep import readers
    from scenegrep.dataset.queries import scenario_rows
    from scenegrep.scenario import ScenarioOptions, load_scenario, load_vocabulary
    from scenegrep.scenario.online import OnlineScenario

    trace = readers.read_trace(real_data / REAL[name])
    trace = replace(trace.slice_frames(0, 60), behaviours=None)
    road_map = readers.read_map(trace.map_source)
    choice = UnknownLayers("permissive")
    offline = label_trace(trace, road_map, unknown_layers=choice).trace
    labeller = OnlineLabeller(road_map, unknown_layers=choice)
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
    rows = scenario_rows(query.match(offline, 10, road_map, options), True, False)
    key = ("start_frame", "end_frame", "correspondence")
    assert len(rows) > 0
    assert sorted(tuple(r[k] for k in key) for r in found) == sorted(tuple(r[k] for k in key) for r in rows)
