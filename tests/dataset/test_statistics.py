"""Catalog statistics equal per-frame, per-object loops over random traces."""

from __future__ import annotations

from collections import Counter

from hypothesis import given

from scenegrep.dataset.statistics import TraceStatistics
from scenegrep.model.taxonomy import kind_of

from ..strategies import label_traces


@given(label_traces())
def test_statistics_equal_brute_force(trace):
    stats = TraceStatistics.of(trace)
    objects = stats.objects.to_pylist()
    for row, object_id in enumerate(trace.objects.id.tolist()):
        frames = [int(f) for f, o in zip(trace.states.frame, trace.states.object) if o == row]
        expected = (min(frames), max(frames), len(frames)) if frames else (-1, -1, 0)
        got = objects[row]
        assert got["object_id"] == object_id
        assert (got["first_frame"], got["last_frame"], got["observations"]) == expected
        assert got["kind"] == kind_of(str(trace.objects.category[row]))
    counts: Counter = Counter()
    for f, o in zip(trace.states.frame.tolist(), trace.states.object.tolist()):
        counts[(f, str(trace.objects.category[o]), "objects")] += 1
    if trace.images is not None:
        boxes = trace.images.boxes
        for sample, code in zip(boxes.sample.tolist(), boxes.category.tolist()):
            counts[(int(trace.images.samples.frame[sample]), boxes.classes[code], "images")] += 1
    rows = stats.frame_counts.to_pylist()
    assert Counter({(r["frame"], r["category"], r["layer"]): r["count"] for r in rows}) == counts
    assert len(rows) == len(counts)
    assert all(r["kind"] == kind_of(r["category"]) for r in rows)
    assert stats.trace["frames"] == trace.n_frames and stats.trace["observations"] == len(trace.states)
    if trace.behaviours is not None:
        labels = {r["label"]: r for r in stats.labels.to_pylist()}
        sets = trace.behaviours.sets()
        for name in trace.behaviours.vocabulary:
            holders = [i for i, s in enumerate(sets) if name in s]
            assert labels[name]["observations"] == len(holders)
            assert labels[name]["objects"] == len({int(trace.states.object[i]) for i in holders})
