"""scenegrep's JSON trace format (see :mod:`scenegrep.readers.trace_json`), written atomically."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import orjson

from ..model import LabelTrace
from .atomic import atomic_path


def _number(value: float) -> float | None:
    return None if math.isnan(value) else float(value)


def _state(trace: LabelTrace, row: int, labels: list[dict[str, Any]] | None) -> dict[str, Any]:
    s = trace.states
    state: dict[str, Any] = {
        "position": [float(s.x[row]), float(s.y[row])] + ([] if math.isnan(s.z[row]) else [float(s.z[row])]),
        "heading": float(s.heading[row]),
    }
    size = [s.length[row], s.width[row]] + ([] if math.isnan(s.height[row]) else [s.height[row]])
    if not any(math.isnan(v) for v in size):
        state["size"] = [float(v) for v in size]
    if not (math.isnan(s.vx[row]) or math.isnan(s.vy[row])):
        state["velocity"] = [float(s.vx[row]), float(s.vy[row])]
    if s.lane[row] >= 0:
        state["lane"] = trace.lane_ids[s.lane[row]]
    if labels is not None:
        state["behaviours"] = labels[row]
    return state


def _labels(trace: LabelTrace) -> list[Any] | None:
    b = trace.behaviours
    if b is None:
        return None
    if b.confidence is None:
        return [sorted(s) for s in b.sets()]
    return [{b.vocabulary[k]: _number(b.confidence[i, k]) for k in row.nonzero()[0]} for i, row in enumerate(b.member)]


def _samples(trace: LabelTrace) -> dict[int, list[dict[str, Any]]]:
    out: dict[int, list[dict[str, Any]]] = {}
    if trace.images is None:
        return out
    samples, boxes = trace.images.samples, trace.images.boxes
    by_sample: dict[int, list[dict[str, Any]]] = {i: [] for i in range(len(samples))}
    for k in range(len(boxes)):
        box: dict[str, Any] = {
            "class": boxes.classes[boxes.category[k]],
            "center": [float(boxes.cx[k]), float(boxes.cy[k])],
            "size": [float(boxes.w[k]), float(boxes.h[k])],
            "score": float(boxes.score[k]),
        }
        if boxes.oriented[k]:
            box["rotation"] = float(boxes.rotation[k])
        if boxes.object[k] >= 0:
            box["object"] = str(trace.objects.id[boxes.object[k]])
        by_sample[int(boxes.sample[k])].append(box)
    for i in range(len(samples)):
        out.setdefault(int(samples.frame[i]), []).append(
            {
                "channel": samples.channels[samples.channel[i]],
                "image": str(samples.image_path[i]),
                "image_size": [int(samples.image_width[i]), int(samples.image_height[i])],
                "boxes": by_sample[i],
            }
        )
    return out


def trace_document(trace: LabelTrace) -> dict[str, Any]:
    """The trace as a JSON-ready document of scenegrep's trace format."""
    labels = _labels(trace)
    samples = _samples(trace)
    frames: list[dict[str, Any]] = []
    offsets = trace.states.frame_offsets(trace.n_frames)
    for f in range(trace.n_frames):
        frame: dict[str, Any] = {"index": int(trace.frame_index[f])}
        if not math.isnan(trace.frame_time[f]):
            frame["time"] = float(trace.frame_time[f])
        frame["objects"] = {
            str(trace.objects.id[trace.states.object[r]]): _state(trace, r, labels)
            for r in range(offsets[f], offsets[f + 1])
        }
        if f in samples:
            frame["samples"] = samples[f]
        frames.append(frame)
    doc: dict[str, Any] = {"scenegrep": "trace", "version": 1, "name": trace.name}
    if trace.ego is not None:
        doc["ego"] = trace.ego
    if trace.map_source is not None:
        doc["map"] = {"path": trace.map_source.path, "format": trace.map_source.format}
        if trace.map_source.key is not None:
            doc["map"]["key"] = trace.map_source.key
    doc["attributes"] = dict(trace.attributes)
    doc["objects"] = {
        str(i): {"class": str(c), "attributes": a}
        for i, c, a in zip(trace.objects.id, trace.objects.category, trace.objects.attributes)
    }
    doc["frames"] = frames
    return doc


def write_trace_json(trace: LabelTrace, path: str | Path) -> Path:
    """Write a trace in scenegrep's JSON format; returns the path."""
    data = orjson.dumps(trace_document(trace), option=orjson.OPT_INDENT_2 | orjson.OPT_SERIALIZE_NUMPY)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data + b"\n")
    return Path(path)
