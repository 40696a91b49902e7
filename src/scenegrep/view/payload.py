"""A :class:`~.data.TraceView` as the JSON document the HTML view reads.

Columns stay columns (one JSON array per field, frames in CSR form: the rows of frame ``f``
are ``offsets[f]:offsets[f + 1]``), rounded to centimetres and milliradians, so a 20 s
recording with ten thousand observations is a few hundred kilobytes. An image view carries
every camera channel (``boxes``: one such table per channel, the one to show first first,
see :func:`.data.image_channels`), so the page can switch between them. Every colour comes
from :mod:`.style` (kinds, classes, program names, behaviour sets), as in the pictures.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import shapely

from ..model import LabelTrace, RoadMap
from .data import TraceView, image_channels
from .style import MARKED_COLOUR, SCENE_COLOURS, behaviour_colours, category_colours, class_colours, program_colours

DIGITS = 2
"""Decimals kept for metres, pixels and radians."""


def payload(view: TraceView) -> dict[str, Any]:
    """The JSON-able document of a view (see the module docstring)."""
    trace = view.trace
    names = [name for match in view.matches for name in match.correspondence]
    doc: dict[str, Any] = {
        "trace_id": view.trace_id,
        "name": trace.name,
        "frames": {"index": trace.frame_index.tolist(), "time": _round(trace.frame_time - trace.frame_time[0], 3)},
        "objects": _objects(trace),
        "space": "image" if view.image_space else "topdown",
        "ego": trace.ego,
        "matches": [
            {
                "number": m.number,
                "first": m.first,
                "last": m.last,
                "correspondence": dict(m.correspondence),
                "explanation": m.explanation,
            }
            for m in view.matches
        ],
        "program_colours": program_colours(names),
        "marked_colour": MARKED_COLOUR,
        "scene_colours": {name: list(pair) for name, pair in SCENE_COLOURS.items()},
        "note": view.note,
        "query": None if view.query is None else {"kind": view.query.kind, "text": view.query.text},
    }
    if view.image_space:
        doc["boxes"] = [_boxes(view, channel) for channel in image_channels(view)]
    else:
        doc["states"] = _states(view)
        doc["map"] = None if view.road_map is None else _map(view.road_map)
    return doc


def _round(values: np.ndarray, digits: int = DIGITS) -> list[float | None]:
    """Rounded values as a list, NaN as null."""
    rounded = np.round(np.asarray(values, dtype=float), digits)
    return [None if v != v else v for v in rounded.tolist()]


def _objects(trace: LabelTrace) -> dict[str, list[str]]:
    colours = class_colours()
    kinds = trace.objects.kinds().tolist()
    return {
        "id": trace.objects.id.tolist(),
        "category": trace.objects.category.tolist(),
        "kind": kinds,
        "colour": [colours[k] for k in kinds],
    }


def _states(view: TraceView) -> dict[str, Any]:
    trace, st = view.trace, view.trace.states
    labels: list[str] = []
    codes: list[int] = []
    if trace.behaviours is not None and len(st):
        labels, found = trace.behaviours.distinct_sets()
        codes = found.tolist()
    return {
        "offsets": st.frame_offsets(trace.n_frames).tolist(),
        "object": st.object.tolist(),
        "x": _round(st.x),
        "y": _round(st.y),
        "heading": _round(st.heading, 3),
        "length": _round(np.nan_to_num(st.length, nan=0.0)),
        "width": _round(np.nan_to_num(st.width, nan=0.0)),
        "speed": _round(st.speed(), 1),
        "label_names": labels,
        "label_colours": behaviour_colours(labels),
        "labels": codes,
        "marked": [] if view.marked is None else view.marked.astype(int).tolist(),
    }


def _boxes(view: TraceView, channel_name: str) -> dict[str, Any]:
    """The boxes of one image channel, grouped by frame, with the colour of every class."""
    assert view.trace.images is not None
    samples, boxes = view.trace.images.samples, view.trace.images.boxes
    channel = samples.channels.index(channel_name)
    rows = np.flatnonzero(samples.channel[boxes.sample] == channel)
    frames = samples.frame[boxes.sample[rows]]
    order = np.argsort(frames, kind="stable")
    rows, frames = rows[order], frames[order]
    sizes = samples.take(samples.channel == channel)
    marked = view.marked_boxes
    return {
        "channel": channel_name,
        "image_size": [int(sizes.image_width.max(initial=0)), int(sizes.image_height.max(initial=0))],
        "offsets": np.searchsorted(frames, np.arange(view.trace.n_frames + 1)).tolist(),
        "classes": list(boxes.classes),
        "class_colours": category_colours(boxes.classes),
        "class": boxes.category[rows].tolist(),
        "object": boxes.object[rows].tolist(),
        "cx": _round(boxes.cx[rows]),
        "cy": _round(boxes.cy[rows]),
        "w": _round(boxes.w[rows]),
        "h": _round(boxes.h[rows]),
        "rotation": _round(boxes.rotation[rows], 3),
        "score": _round(boxes.score[rows], 3),
        "marked": [] if marked is None else marked[rows].astype(int).tolist(),
    }


def _map(road_map: RoadMap) -> dict[str, list[list[list[float]]]]:
    """Lanes, intersections and crosswalks as lists of rings (each a list of [x, y])."""
    return {
        "lanes": rings([lane.polygon for lane in road_map.lanes]),
        "intersections": rings([area.polygon for area in road_map.intersections]),
        "crosswalks": rings([area.polygon for area in road_map.crosswalks]),
    }


def rings(polygons: list[Any]) -> list[list[list[float]]]:
    """The exterior rings of (multi)polygons, simplified to centimetres."""
    if not polygons:
        return []
    parts = shapely.get_parts(shapely.simplify(np.array(polygons, dtype=object), 0.05))
    exteriors = shapely.get_exterior_ring(parts[shapely.get_type_id(parts) == 3])
    return [np.round(shapely.get_coordinates(ring), DIGITS).tolist() for ring in exteriors]
