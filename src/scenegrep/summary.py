"""Summaries of traces and maps: what ``scenegrep info`` prints, as plain data."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from .model import LabelTrace, RoadMap


def _rate(trace: LabelTrace) -> float | None:
    steps = np.diff(trace.frame_time)
    steps = steps[np.isfinite(steps) & (steps > 0)]
    return float(1.0 / np.median(steps)) if len(steps) else None


def trace_summary(trace: LabelTrace) -> dict[str, Any]:
    """Counts of a trace: frames, duration (s, None when frames have no times), rate (Hz),
    objects per class, states, lanes labelled, behaviour label counts, image samples and boxes."""
    summary: dict[str, Any] = {
        "name": trace.name,
        "format": trace.source.format if trace.source else None,
        "frames": trace.n_frames,
        "duration_s": None if math.isnan(trace.duration) else round(trace.duration, 6),
        "rate_hz": _rate(trace),
        "objects": trace.n_objects,
        "ego": trace.ego,
        "objects_per_class": dict(Counter(trace.objects.category.tolist()).most_common()),
        "states": len(trace.states),
        "states_with_lane": int(np.sum(trace.states.lane >= 0)),
        "attributes": dict(trace.attributes),
    }
    if trace.behaviours is not None:
        counts = trace.behaviours.member.sum(axis=0)
        summary["behaviour_labels"] = {name: int(c) for name, c in zip(trace.behaviours.vocabulary, counts)}
    if trace.images is not None:
        samples, boxes = trace.images.samples, trace.images.boxes
        summary["image_samples_per_channel"] = {
            samples.channels[c]: int(n) for c, n in zip(*np.unique(samples.channel, return_counts=True))
        }
        summary["image_boxes_per_class"] = {
            boxes.classes[c]: int(n) for c, n in zip(*np.unique(boxes.category, return_counts=True))
        }
    if trace.map_source is not None:
        summary["map_source"] = {
            "path": trace.map_source.path,
            "format": trace.map_source.format,
            "key": trace.map_source.key,
        }
    return summary


def map_summary(road_map: RoadMap) -> dict[str, Any]:
    """Counts of a map's elements, the layers its format does not publish (unknown, not empty) and
    its extent in metres."""
    min_x, min_y, max_x, max_y = road_map.bounds() if road_map.lanes else (0.0, 0.0, 0.0, 0.0)
    return {
        "name": road_map.name,
        "lanes": len(road_map.lanes),
        "intersection_lanes": int(road_map.lane_is_intersection.sum()) if road_map.lanes else 0,
        "roads": len(road_map.roads),
        "intersections": len(road_map.intersections),
        "crosswalks": len(road_map.crosswalks),
        "sidewalks": len(road_map.sidewalks),
        "curbs": len(road_map.curbs),
        "stop_lines": len(road_map.stop_lines),
        "unknown_layers": sorted(road_map.unknown_layers),
        "extent_m": [round(max_x - min_x, 1), round(max_y - min_y, 1)],
    }


def describe(path: str | Path, with_map: bool = True) -> dict[str, Any]:
    """Summary of any supported input: its format, its traces and its map."""
    from . import readers

    format_name = readers.detect_format(path)
    spec = readers.FORMATS[format_name]
    out: dict[str, Any] = {"path": str(path), "format": format_name, "description": spec.description}
    if format_name == "ros-bag":
        from .readers.ros.bag import topic_table

        out["topics"] = topic_table(path)
    traces = list(readers.read_traces(path, format_name)) if spec.traces else []
    out["traces"] = [trace_summary(t) for t in traces]
    if with_map:
        if spec.map and not spec.traces:
            out["maps"] = [map_summary(readers.read_map(path, format_name))]
        else:
            sources = list(dict.fromkeys(t.map_source for t in traces if t.map_source is not None))
            out["maps"] = [map_summary(readers.read_map(s)) for s in sources]
    return out
