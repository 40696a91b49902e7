"""What the catalog knows about a trace without reading it: counts computed once at ingest.

Everything here is a function of one :class:`LabelTrace`, vectorised over its state and box
rows. Frames are positions 0..F-1 of the trace (not the dataset's frame indices); times are
seconds from the trace's first frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from ..model import LabelTrace
from ..model.taxonomy import kind_of


@dataclass(frozen=True)
class TraceStatistics:
    """The catalog rows of one trace: ``trace`` (one row as a dict), and Arrow tables
    ``objects`` (one row per object), ``frame_counts`` (objects or boxes per class per frame)
    and ``labels`` (behaviour label statistics); none carries the trace id yet."""

    trace: dict[str, Any]
    objects: pa.Table
    frame_counts: pa.Table
    labels: pa.Table

    @classmethod
    def of(cls, trace: LabelTrace) -> TraceStatistics:
        """Compute the statistics of ``trace``."""
        return cls(_trace_row(trace), _objects(trace), _frame_counts(trace), _labels(trace))


def _trace_row(trace: LabelTrace) -> dict[str, Any]:
    return {
        "name": trace.name,
        "frames": trace.n_frames,
        "duration_s": trace.duration,
        "period_s": trace.frame_period,
        "objects": trace.n_objects,
        "observations": len(trace.states),
        "ego": trace.ego,
        "has_behaviours": trace.behaviours is not None,
        "has_images": trace.images is not None,
        "time_origin_ns": time_origin_ns(trace),
    }


def time_origin_ns(trace: LabelTrace) -> int:
    """The absolute time of the trace's time 0 in nanoseconds (the dataset's epoch, usually Unix
    time), from the reader's ``time_origin_ns`` or ``time_origin_s`` attribute; 0 when it has none."""
    attributes = trace.attributes
    for key, scale in (("time_origin_ns", 1), ("time_origin_s", 1_000_000_000)):
        value = attributes.get(key)
        if isinstance(value, int | float | np.integer | np.floating):
            return int(round(float(value) * scale)) if scale != 1 else int(value)
    return 0


def _objects(trace: LabelTrace) -> pa.Table:
    frames, rows = trace.states.frame, trace.states.object
    n = trace.n_objects
    first = np.full(n, np.iinfo(np.int64).max)
    last = np.full(n, -1)
    np.minimum.at(first, rows, frames)
    np.maximum.at(last, rows, frames)
    categories = trace.objects.category.astype(str)
    return pa.table(
        {
            "object_id": pa.array(trace.objects.id.astype(str).tolist(), pa.string()),
            "category": pa.array(categories.tolist(), pa.string()),
            "kind": pa.array(trace.objects.kinds().astype(str).tolist(), pa.string()),
            "first_frame": pa.array(np.where(last >= 0, first, -1), pa.int64()),
            "last_frame": pa.array(last, pa.int64()),
            "observations": pa.array(np.bincount(rows, minlength=n), pa.int64()),
        }
    )


def _count_by(frames: np.ndarray, codes: np.ndarray, names: np.ndarray, layer: str) -> dict[str, list]:
    """Rows (frame, category, kind, layer, count) of the pairs (frame, code) with their counts."""
    if len(frames) == 0:
        return {"frame": [], "category": [], "kind": [], "layer": [], "count": []}
    width = len(names)
    keys, counts = np.unique(frames.astype(np.int64) * width + codes, return_counts=True)
    category = names[keys % width]
    kinds = np.array([kind_of(str(c)) for c in names], dtype=object)[keys % width]
    return {
        "frame": (keys // width).tolist(),
        "category": category.tolist(),
        "kind": kinds.tolist(),
        "layer": [layer] * len(keys),
        "count": counts.tolist(),
    }


def _frame_counts(trace: LabelTrace) -> pa.Table:
    names, codes = np.unique(trace.objects.category.astype(str), return_inverse=True)
    parts = [_count_by(trace.states.frame, codes.reshape(-1)[trace.states.object], names.astype(object), "objects")]
    if trace.images is not None:
        boxes = trace.images.boxes
        frames = trace.images.samples.frame[boxes.sample]
        parts.append(_count_by(frames, boxes.category, np.array(boxes.classes, dtype=object), "images"))
    columns = {key: sum((p[key] for p in parts), []) for key in parts[0]}
    return pa.table(
        {
            "frame": pa.array(columns["frame"], pa.int64()),
            "category": pa.array(columns["category"], pa.string()),
            "kind": pa.array(columns["kind"], pa.string()),
            "layer": pa.array(columns["layer"], pa.string()),
            "count": pa.array(columns["count"], pa.int64()),
        }
    )


def _labels(trace: LabelTrace) -> pa.Table:
    labels = trace.behaviours
    if labels is None:
        return pa.table(
            {
                "label": pa.array([], pa.string()),
                "observations": pa.array([], pa.int64()),
                "objects": pa.array([], pa.int64()),
            }
        )
    member = labels.member.astype(bool)
    per_object = np.zeros((trace.n_objects, member.shape[1]), dtype=bool)
    np.logical_or.at(per_object, trace.states.object, member)
    return pa.table(
        {
            "label": pa.array(list(labels.vocabulary), pa.string()),
            "observations": pa.array(member.sum(axis=0), pa.int64()),
            "objects": pa.array(per_object.sum(axis=0), pa.int64()),
        }
    )
