"""Moments: a match row as the labeled objects' paths over its window (the exporters' input),
checked on hand-built traces and, for ``context``, against a brute-force reference on random ones."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.dataset.moments import MAX_CONTEXT_M, moment_of, moments
from scenegrep.dataset.queries import results_table
from scenegrep.dataset.results import Results
from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, MapSource, ObjectTable, StateTable


def street(times=None, ego: str | None = "ego") -> LabelTrace:
    """10 frames (dataset indices 100..109, 10 Hz): the ego along +x at 1 m per frame, car 'c'
    parked 10 m north (lengths 4.0 and 4.4 in turn, no height), pedestrian 'w' 30 m east of the
    origin from frame 104 on, truck 't' 100 m away."""
    frames = np.arange(10)
    objects = ObjectTable.build(["c", "ego", "t", "w"], ["vehicle.car", "car", "vehicle.truck", "human.pedestrian"])
    rows = [(f, 0, 0.0, 10.0, 0.0, 4.0 + 0.4 * (f % 2)) for f in frames]
    rows += [(f, 1, float(f), 0.0, -math.pi / 2, 4.5) for f in frames]
    rows += [(f, 2, 100.0, 0.0, 0.0, 8.0) for f in frames]
    rows += [(f, 3, 30.0, 0.0, math.pi, 0.5) for f in frames if f >= 4]
    f, o, x, y, h, length = (np.array(v) for v in zip(*rows))
    n = len(f)
    states = StateTable.build(
        frame=f, object=o, x=x, y=y, z=np.full(n, 0.5), heading=h, length=length, width=np.full(n, 2.0)
    )
    return LabelTrace.build(
        "street",
        frames + 100,
        frames / 10 if times is None else times,
        objects,
        states,
        ego=ego,
        map_source=MapSource("town.xodr", "opendrive"),
    )


def row(correspondence, first: int = 102, last: int = 106, number: int = 0) -> dict:
    text = correspondence if isinstance(correspondence, str) else json.dumps(correspondence)
    return {
        "trace_id": "t1",
        "name": "street",
        "status": "match",
        "match": number,
        "correspondence": text,
        "start_frame": first,
        "end_frame": last,
    }


def test_a_moment_holds_the_ego_then_the_corresponded_objects_over_the_window():
    moment = moment_of(street(), row({"car": "c", "ego": "ego"}))
    assert [o.label_id for o in moment.objects] == ["ego", "c"]
    assert [o.program_name for o in moment.objects] == ["ego", "car"]
    assert (moment.start_frame, moment.end_frame, moment.match, moment.ego) == (102, 106, 0, "ego")
    assert moment.start_time == pytest.approx(0.2) and moment.duration == pytest.approx(0.4)
    assert moment.frame_period == pytest.approx(0.1) and moment.map_source == MapSource("town.xodr", "opendrive")
    ego, car = moment.objects
    assert ego.times == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4]) and ego.x.tolist() == [2.0, 3.0, 4.0, 5.0, 6.0]
    assert ego.heading.tolist() == [-math.pi / 2] * 5 and ego.z.tolist() == [0.5] * 5
    assert car.category == "vehicle.car" and car.y.tolist() == [10.0] * 5
    # sizes: the median over the window (4.0, 4.4, 4.0, 4.4, 4.0 -> 4.0); unknown height -> NaN
    assert (car.length, car.width) == (4.0, 2.0) and math.isnan(car.height)


def test_an_object_observed_in_part_of_the_window_has_only_its_observations():
    moment = moment_of(street(), row({"ego": "ego", "p": "w"}, 102, 106))
    walker = moment.objects[1]
    assert walker.times == pytest.approx([0.2, 0.3, 0.4]) and walker.x.tolist() == [30.0] * 3


def test_without_a_trace_ego_the_objects_follow_the_correspondence():
    moment = moment_of(street(ego=None), row({"car": "c", "ego": "ego"}))
    assert moment.ego is None and [o.label_id for o in moment.objects] == ["c", "ego"]


def test_context_adds_the_objects_within_the_radius_in_some_frame_by_label_id():
    trace = street()
    assert [o.label_id for o in moment_of(trace, row({"ego": "ego"}, 100, 103), 10.0).objects] == ["ego", "c"]
    # 'w' appears at frame 104, 30 m east of the origin: 26 m from the ego then, 23 m at frame 107
    near = moment_of(trace, row({"ego": "ego"}, 100, 107), 23.0).objects
    assert [o.label_id for o in near] == ["ego", "c", "w"]
    assert [o.label_id for o in moment_of(trace, row({"ego": "ego"}, 100, 106), 23.0).objects] == ["ego", "c"]
    assert [o.program_name for o in near] == ["ego", None, None]
    assert [o.label_id for o in moment_of(trace, row({"ego": "ego"}, 100, 109), 0.0).objects] == ["ego"]


@pytest.mark.parametrize("radius", [-1.0, math.nan, math.inf, MAX_CONTEXT_M * 1.01])
def test_a_context_radius_out_of_range_is_a_user_error(radius):
    results = Results(results_table([row({"ego": "ego"})]))
    with pytest.raises(UserError, match="--context"):
        list(moments(results, lambda _: street(), radius))


@pytest.mark.parametrize(
    "bad, message",
    [
        (row("not json"), "correspondence is not scenegrep's"),
        (row("[1, 2]"), "correspondence is not scenegrep's"),
        (row({"ego": "nobody"}), "no object 'nobody'"),
        (row({"ego": "ego"}, 200, 210), "frames 200..210 are not in the trace"),
        (row({"ego": "w"}, 100, 102), "not observed in the match's window"),
    ],
)
def test_rows_that_do_not_fit_the_trace_are_user_errors(bad, message):
    with pytest.raises(UserError, match=message):
        moment_of(street(), bad)


def test_a_window_with_unknown_frame_times_is_a_user_error():
    times = np.arange(10) / 10
    times[3] = np.nan
    with pytest.raises(UserError, match="no time"):
        moment_of(street(times), row({"ego": "ego"}, 102, 104))
    assert moment_of(street(times), row({"ego": "ego"}, 104, 106)).frame_period == pytest.approx(0.1)


def test_moments_load_each_trace_once_and_skip_rows_that_are_not_matches():
    rows = [row({"ego": "ego"}), row({"ego": "ego"}, 104, 105, 1), {"trace_id": "t2", "name": "x", "status": "failed"}]
    loads = []
    found = list(moments(Results(results_table(rows)), lambda t: loads.append(t) or street()))
    assert [m.match for m in found] == [0, 1] and loads == ["t1"]


# ----------------------------------------------------------------------------- context, brute force
@st.composite
def crowds(draw):
    """A random trace of 3..6 objects over 4 frames (some unobserved), a window and a radius."""
    n_objects = draw(st.integers(3, 6))
    cells = [(f, o) for f in range(4) for o in range(n_objects) if o < 2 or draw(st.booleans())]
    xy = st.floats(-30, 30, allow_nan=False)
    positions = [(draw(xy), draw(xy)) for _ in cells]
    f, o = (np.array(v) for v in zip(*cells))
    states = StateTable.build(
        frame=f, object=o, x=[p[0] for p in positions], y=[p[1] for p in positions], heading=np.zeros(len(cells))
    )
    ids = [f"o{i}" for i in range(n_objects)]
    trace = LabelTrace.build(
        "crowd", np.arange(4), np.arange(4) / 10, ObjectTable.build(ids, ["car"] * n_objects), states
    )
    first = draw(st.integers(0, 3))
    return trace, first, draw(st.integers(first, 3)), draw(st.floats(0, 40))


@settings(max_examples=60)
@given(crowds())
def test_context_equals_a_brute_force_search(case):
    trace, first, last, radius = case
    moment = moment_of(trace, row({"a": "o0", "b": "o1"}, first, last), radius)
    s = trace.states
    expected = {
        f"o{s.object[i]}"
        for i in range(len(s))
        for j in range(len(s))
        if first <= s.frame[i] <= last
        and s.frame[i] == s.frame[j]
        and s.object[j] < 2 <= s.object[i]
        and math.hypot(s.x[i] - s.x[j], s.y[i] - s.y[j]) <= radius
    }
    assert [o.label_id for o in moment.objects] == ["o0", "o1", *sorted(expected)]
