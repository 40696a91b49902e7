"""The vectorised track operations against per-segment Python loops (brute force)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.label.tracks import Tracks
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.model.geometry import normalize_angle

TAU = 2 * math.pi


@st.composite
def traces(draw):
    """A trace of up to 4 objects over up to 30 frames with irregular times and gaps."""
    n_frames = draw(st.integers(1, 30))
    steps = draw(st.lists(st.sampled_from([0.1, 0.1, 0.2, 1.5]), min_size=n_frames, max_size=n_frames))
    time = np.cumsum([0.0] + steps[:-1])
    n_objects = draw(st.integers(1, 4))
    present = draw(st.lists(st.booleans(), min_size=n_frames * n_objects, max_size=n_frames * n_objects))
    frame, obj = np.nonzero(np.array(present).reshape(n_frames, n_objects))
    values = st.floats(-10, 10, allow_nan=False)
    n = len(frame)
    x = np.array(draw(st.lists(values, min_size=n, max_size=n)))
    heading = normalize_angle(np.array(draw(st.lists(st.floats(-7, 7), min_size=n, max_size=n))))
    states = StateTable.build(frame, obj, x, x, heading)
    objects = ObjectTable.build([f"o{k}" for k in range(n_objects)], ["car"] * n_objects)
    return LabelTrace.build("t", np.arange(n_frames), time, objects, states)


def segments(trace: LabelTrace, max_gap: float) -> list[list[int]]:
    """State rows per segment, by brute force."""
    out = []
    for k in range(trace.n_objects):
        rows = [i for i in range(len(trace.states)) if trace.states.object[i] == k]
        for i in rows:
            t = trace.frame_time[trace.states.frame[i]]
            if (
                out
                and out[-1]
                and out[-1][-1] in rows
                and t - trace.frame_time[trace.states.frame[out[-1][-1]]] <= max_gap
            ):
                out[-1].append(i)
            else:
                out.append([i])
    return out


@settings(max_examples=150, deadline=None)
@given(trace=traces(), half=st.integers(1, 4))
def test_windows_gradients_and_unwrapping_stay_inside_segments(trace, half):
    tracks = Tracks.of(trace, max_gap_s=1.0)
    x = trace.states.x[tracks.order]
    heading = trace.states.heading[tracks.order]
    position = {row: p for p, row in enumerate(tracks.order.tolist())}
    mean, slope = tracks.window_mean(x, half), tracks.gradient(x)
    turns = tracks.turns(heading)
    smoothed, yaw_rate = tracks.angle_mean(heading, turns, half), tracks.gradient(heading, turns)
    for rows in segments(trace, 1.0):
        ps = [position[r] for r in rows]
        times = [trace.frame_time[trace.states.frame[r]] for r in rows]
        unwrapped = np.unwrap(heading[ps])  # brute force: steps of at most pi, from the first heading
        for j, p in enumerate(ps):
            window = ps[max(0, j - half) : j + half + 1]
            assert math.isclose(mean[p], np.mean(x[window]), abs_tol=1e-9)
            a, b = max(j - 1, 0), min(j + 1, len(ps) - 1)
            dt = times[b] - times[a]
            expected = (x[ps[b]] - x[ps[a]]) / dt if dt > 0 else np.nan
            assert np.isclose(slope[p], expected, equal_nan=True)
            assert np.isclose(yaw_rate[p], (unwrapped[b] - unwrapped[a]) / dt if dt > 0 else np.nan, equal_nan=True)
            base = heading[p] + TAU * (turns[p] - turns[ps[0]])  # heading p unwrapped from the first
            assert math.isclose(base, unwrapped[j], abs_tol=1e-9)
            window_unwrapped = unwrapped[max(0, j - half) : j + half + 1]
            assert math.isclose(smoothed[p] - heading[p] + base, np.mean(window_unwrapped), abs_tol=1e-9)


@settings(max_examples=100, deadline=None)
@given(
    values=st.lists(st.floats(-1e3, 1e3), min_size=2, max_size=30),
    angles=st.lists(st.floats(-7, 7), min_size=2, max_size=30),
    earlier=st.lists(st.floats(-1e3, 1e3), max_size=30),
    half=st.integers(1, 6),
)
def test_window_values_do_not_depend_on_earlier_observations(values, angles, earlier, half):
    """One object's track with or without earlier observations of it: every value whose window
    lies in the shorter track is bit for bit the same (no running sum over the segment)."""
    n = min(len(values), len(angles))
    values, angles = np.array(values[:n]), normalize_angle(np.array(angles[:n]))
    k = len(earlier)

    times = np.arange(k + n) * 0.1

    def of(xs, hs):
        m = len(xs)
        states = StateTable.build(np.arange(m), np.zeros(m, int), xs, xs, hs)
        trace = LabelTrace.build("t", np.arange(m), times[-m:], ObjectTable.build(["o"], ["car"]), states)
        tracks = Tracks.of(trace, max_gap_s=1.0, interval=0.1)
        turns = tracks.turns(hs)
        return tracks.window_mean(xs, half), tracks.angle_mean(hs, turns, half), tracks.gradient(hs, turns)

    short = of(values, angles)
    long = of(np.r_[earlier, values], np.r_[normalize_angle(np.array(earlier)), angles])
    for got, expected in zip(short, long, strict=True):
        assert np.array_equal(got[half:], expected[k + half :], equal_nan=True)


@settings(max_examples=150, deadline=None)
@given(trace=traces(), data=st.data())
def test_runs_any_and_forward_fill(trace, data):
    tracks = Tracks.of(trace, max_gap_s=1.0)
    n = len(tracks)
    flags = np.array(data.draw(st.lists(st.booleans(), min_size=n, max_size=n)), dtype=bool)
    codes = np.array(data.draw(st.lists(st.integers(-1, 3), min_size=n, max_size=n)), dtype=np.intp)
    first, last = tracks.runs(flags)
    near = tracks.window_any(flags, 2)
    filled = tracks.forward_fill(codes)
    position = {row: p for p, row in enumerate(tracks.order.tolist())}
    for rows in segments(trace, 1.0):
        ps = [position[r] for r in rows]
        for j, p in enumerate(ps):
            assert near[p] == any(flags[q] for q in ps[max(0, j - 2) : j + 3])
            known = [codes[q] for q in ps[: j + 1] if codes[q] != -1]
            assert filled[p] == (known[-1] if known else -1)
            if flags[p]:
                run_start = j
                while run_start > 0 and flags[ps[run_start - 1]]:
                    run_start -= 1
                run_end = j
                while run_end + 1 < len(ps) and flags[ps[run_end + 1]]:
                    run_end += 1
                assert (first[p], last[p]) == (ps[run_start], ps[run_end])
