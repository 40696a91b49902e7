"""LabelTrace: invariants, dense views, slicing by time and by object (against brute force)."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.model import states as states_module
from scenegrep.model import trace as trace_module
from tests.strategies import label_traces


def small_trace() -> LabelTrace:
    objects = ObjectTable.build(["a", "b"], ["car", "pedestrian"])
    states = StateTable.build([1, 0, 0, 2], [0, 1, 0, 0], [1.0, 5.0, 0.0, 2.0], [0, 0, 0, 0], [0, 0, 0, 0])
    labels = BehaviourLabels.from_sets([{"F"}, {"S"}, {"G"}, {"F", "L"}])
    return LabelTrace.build("t", [10, 11, 12], [0.0, 0.1, 0.2], objects, states, behaviours=labels, ego="a")


def test_build_sorts_states_and_labels_together():
    t = small_trace()
    assert t.states.frame.tolist() == [0, 0, 1, 2] and t.states.object.tolist() == [0, 1, 0, 0]
    assert t.states.x.tolist() == [0.0, 5.0, 1.0, 2.0]
    assert t.behaviours.sets() == [{"G"}, {"S"}, {"F"}, {"F", "L"}]


def test_validate_rejects_duplicates_and_bad_codes():
    objects = ObjectTable.build(["a"], ["car"])
    with pytest.raises(ValueError, match="duplicates"):
        LabelTrace.build("t", [0], [0.0], objects, StateTable.build([0, 0], [0, 0], [0, 0], [0, 0], [0, 0]))
    with pytest.raises(ValueError, match="object out of range"):
        LabelTrace.build("t", [0], [0.0], objects, StateTable.build([0], [1], [0], [0], [0]))
    with pytest.raises(ValueError, match="ego"):
        LabelTrace.build("t", [0], [0.0], objects, StateTable.build([0], [0], [0], [0], [0]), ego="zz")
    with pytest.raises(ValueError, match="unique"):
        ObjectTable.build(["a", "a"], ["car", "car"])


def test_build_checks_the_row_order_once_and_still_refuses_bad_rows(monkeypatch):
    objects = ObjectTable.build(["a", "b"], ["car", "car"])
    calls = []
    in_order = StateTable.in_order
    monkeypatch.setattr(StateTable, "in_order", lambda self, n: calls.append(n) or in_order(self, n))
    LabelTrace.build(
        "t", [0, 1], [0.0, 0.1], objects, StateTable.build([0, 0, 1], [0, 1, 1], [0] * 3, [0] * 3, [0] * 3)
    )
    assert len(calls) == 1  # (found in order: not checked again)
    LabelTrace.build(
        "t", [0, 1], [0.0, 0.1], objects, StateTable.build([1, 0, 0], [1, 0, 1], [0] * 3, [0] * 3, [0] * 3)
    )
    assert len(calls) == 3  # (sorted, then checked)
    with pytest.raises(ValueError, match="duplicates"):  # (duplicates found after the sort)
        LabelTrace.build(
            "t", [0, 1], [0.0, 0.1], objects, StateTable.build([1, 0, 1], [0, 0, 0], [0] * 3, [0] * 3, [0] * 3)
        )
    with pytest.raises(ValueError, match="object out of range"):  # (in order, but not objects of the trace)
        LabelTrace.build("t", [0], [0.0], objects, StateTable.build([0, 0], [-1, 0], [0] * 2, [0] * 2, [0] * 2))
    with pytest.raises(ValueError, match="object out of range"):
        LabelTrace.build("t", [0], [0.0], objects, StateTable.build([0, 0], [0, 2], [0] * 2, [0] * 2, [0] * 2))


@pytest.mark.parametrize("at", [1, 2, 3, 4, 5])
def test_row_order_and_values_are_checked_across_blocks(monkeypatch, at):
    monkeypatch.setattr(states_module, "BLOCK", 2)
    monkeypatch.setattr(trace_module, "BLOCK", 2)
    objects = ObjectTable.build(["a", "b"], ["car", "car"])
    frames, ids = [0, 0, 1, 1, 2, 2, 3], [0, 1, 0, 1, 0, 1, 0]
    assert StateTable.build(frames, ids, [0] * 7, [0] * 7, [0] * 7).in_order(2)
    frames[at], frames[at - 1] = frames[at - 1], frames[at]  # (swapped across or inside a block)
    ids[at], ids[at - 1] = ids[at - 1], ids[at]
    assert not StateTable.build(frames, ids, [0] * 7, [0] * 7, [0] * 7).in_order(2)
    x = [0.0] * 7
    x[at] = np.inf
    with pytest.raises(ValueError, match="x is inf"):
        LabelTrace.build(
            "t",
            range(4),
            np.arange(4.0),
            objects,
            StateTable.build([0, 0, 1, 1, 2, 2, 3], [0, 1, 0, 1, 0, 1, 0], x, [0] * 7, [0] * 7),
        )
    length = [1.0] * 7
    length[at] = -1.0
    with pytest.raises(ValueError, match="length is -1.0"):
        LabelTrace.build(
            "t",
            range(4),
            np.arange(4.0),
            objects,
            StateTable.build([0, 0, 1, 1, 2, 2, 3], [0, 1, 0, 1, 0, 1, 0], [0] * 7, [0] * 7, [0] * 7, length=length),
        )


def test_dense_and_present():
    t = small_trace()
    assert t.present().tolist() == [[True, True], [True, False], [True, False]]
    x = t.dense("x")
    assert x[0].tolist() == [0.0, 5.0] and np.isnan(x[1, 1])


@given(label_traces(), st.integers(-2, 10), st.integers(-2, 10))
def test_slice_frames_matches_brute_force(trace, start, stop):
    sliced = trace.slice_frames(start, stop)
    kept = list(range(trace.n_frames))[start:stop]
    assert sliced.frame_index.tolist() == trace.frame_index[kept].tolist()
    expected = {
        (kept.index(f), trace.objects.id[o], x)
        for f, o, x in zip(trace.states.frame, trace.states.object, trace.states.x)
        if f in kept
    }
    got = {(f, sliced.objects.id[o], x) for f, o, x in zip(sliced.states.frame, sliced.states.object, sliced.states.x)}
    assert got == expected
    if trace.behaviours is not None:
        before = {
            (kept.index(f), trace.objects.id[o], s)
            for f, o, s in zip(trace.states.frame, trace.states.object, trace.behaviours.sets())
            if f in kept
        }
        after = set(zip(sliced.states.frame, sliced.objects.id[sliced.states.object], sliced.behaviours.sets()))
        assert after == before
    if trace.images is not None:
        boxes_before = sorted(
            (kept.index(trace.images.samples.frame[s]), x)
            for s, x in zip(trace.images.boxes.sample, trace.images.boxes.cx)
            if trace.images.samples.frame[s] in kept
        )
        boxes_after = sorted(zip(sliced.images.samples.frame[sliced.images.boxes.sample], sliced.images.boxes.cx))
        assert boxes_after == boxes_before
    sliced.validate()


@given(label_traces(), st.floats(-0.5, 2.0), st.floats(0.0, 3.0))
def test_between_keeps_frames_in_closed_interval(trace, t0, length):
    sliced = trace.between(t0, t0 + length)
    assert sliced.frame_time.tolist() == [t for t in trace.frame_time if t0 <= t <= t0 + length]


@given(label_traces(), st.data())
def test_select_objects(trace, data):
    chosen = data.draw(st.lists(st.sampled_from(trace.objects.id.tolist()), unique=True)) if trace.n_objects else []
    sub = trace.select_objects(chosen)
    assert sorted(sub.objects.id.tolist()) == sorted(chosen)
    assert sub.n_frames == trace.n_frames
    expected = sorted(
        (f, trace.objects.id[o])
        for f, o in zip(trace.states.frame, trace.states.object)
        if trace.objects.id[o] in chosen
    )
    assert sorted((f, sub.objects.id[o]) for f, o in zip(sub.states.frame, sub.states.object)) == expected


def test_select_unknown_object_raises():
    with pytest.raises(KeyError):
        small_trace().select_objects(["nope"])


def test_behaviour_threshold_keeps_unscored_labels():
    labels = BehaviourLabels.from_sets([{"F": 0.9, "L": 0.2}, {"S": None}])
    assert labels.thresholded(0.5).sets() == [{"F"}, {"S"}]


def test_select_frames_keeps_every_object():
    from tests.label.tracks import trace_of

    x = np.full(4, 1.75)
    trace = trace_of(("car", x, np.arange(4.0), None), ("car", x[:2] + 3.5, np.arange(2.0), None))
    kept = trace.select_frames(np.array([False, False, True, True]))
    assert kept.n_frames == 2 and kept.n_objects == 2 and len(kept.states) == 2
    assert kept.frame_time.tolist() == trace.frame_time[2:].tolist()


@given(label_traces(), st.data())
def test_concatenate_puts_frames_one_after_the_other_with_objects_by_id(trace, data):
    from scenegrep.model import concatenate

    if trace.images is not None:
        trace = replace(trace, images=None)
    cut = data.draw(st.integers(0, trace.n_frames))
    joined = concatenate([trace.slice_frames(0, cut), trace.slice_frames(cut, trace.n_frames)])
    assert joined.n_frames == trace.n_frames
    assert np.array_equal(joined.frame_index, trace.frame_index)
    for obj in set(trace.objects.id[trace.states.object].tolist()):
        a = joined.states.take(joined.states.object == joined.object_index(obj))
        b = trace.states.take(trace.states.object == trace.object_index(obj))
        assert np.array_equal(a.frame, b.frame) and np.array_equal(a.x, b.x, equal_nan=True)
        if trace.behaviours is not None:
            rows_a = np.flatnonzero(joined.states.object == joined.object_index(obj))
            rows_b = np.flatnonzero(trace.states.object == trace.object_index(obj))
            sets_a, sets_b = joined.behaviours.sets(), trace.behaviours.sets()
            assert [sets_a[r] for r in rows_a] == [sets_b[r] for r in rows_b]
