"""What a view shows: one trace on its road map and the matches of a query over it.

A :class:`TraceView` holds a trace, its road map cropped to where the trace's objects go,
the matches of a query over the trace (:class:`MatchView`: the window as frame positions,
the correspondence from the program's names to object ids, the explanation), why the trace
does not match when it does not (``note``), and, for a SpRE, which observations belong to
the classes the query names (``marked``). The faces draw from it: :mod:`.plot` (PNG and GIF
through matplotlib) and :mod:`.page` (a self-contained HTML page).
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..dataset.results_traces import QueryInfo
from ..errors import UserError
from ..model import LabelTrace, RoadMap

MAP_MARGIN = 25.0
"""Metres of road map kept around the area the trace's objects cover."""


@dataclass(frozen=True)
class MatchView:
    """One match over a trace: ``number`` (the results' match number within the trace), the
    window's first and last frame positions (inclusive), the correspondence (program name or
    track variable -> object id) and the explanation text ('' when the run did not explain)."""

    number: int
    first: int
    last: int
    correspondence: Mapping[str, str]
    explanation: str = ""


@dataclass(frozen=True, eq=False)
class TraceView:
    """A trace to draw; see the module docstring. ``marked`` is a boolean per state row (top-down
    space) and ``marked_boxes`` one per image box, or None when the query names no classes."""

    trace: LabelTrace
    road_map: RoadMap | None = None
    matches: tuple[MatchView, ...] = ()
    note: str = ""
    query: QueryInfo | None = None
    trace_id: str = ""
    marked: np.ndarray | None = None
    marked_boxes: np.ndarray | None = None

    @property
    def image_space(self) -> bool:
        """Whether the view draws image boxes (a trace of detections only, or a SpRE run in the image space)."""
        if self.trace.images is None or len(self.trace.images.boxes) == 0:
            return False
        if len(self.trace.states) == 0:
            return True
        return self.query is not None and self.query.kind == "spre" and self.query.options.get("space") != "topdown"

    def match(self, number: int) -> MatchView:
        """The match with this results number (UserError if the trace has none such)."""
        for match in self.matches:
            if match.number == number:
                return match
        raise UserError(f"trace {self.trace.name!r} has no match {number} (it has {len(self.matches)})")


def build_view(
    trace: LabelTrace,
    road_map: RoadMap | None = None,
    rows: Iterable[Mapping[str, Any]] = (),
    query: QueryInfo | None = None,
    trace_id: str = "",
) -> TraceView:
    """The view of ``trace`` with the results rows of it (the results table's columns; rows of
    other traces must be filtered out before). The map is cropped to the trace's area."""
    matches, notes = [], []
    positions = frame_positions(trace)
    for row in rows:
        if row["status"] == "match":
            matches.append(_match_view(trace, positions, row))
        elif row.get("explanation") or row.get("error"):
            at = "" if row.get("start_frame") is None else f" at frame {row['start_frame']}"
            notes.append(f"{row['status']}{at}: {row.get('error') or row.get('explanation')}")
    marked, marked_boxes = _marked(trace, query) if query is not None and query.kind == "spre" else (None, None)
    return TraceView(
        trace,
        None if road_map is None else crop_to_trace(road_map, trace),
        tuple(matches),
        "\n".join(notes),
        query,
        trace_id or trace.name,
        marked,
        marked_boxes,
    )


def image_channels(view: TraceView) -> tuple[str, ...]:
    """The camera channels an image view draws, the one to show first first: the channels the
    SpRE ran on (``--channel``, in its order), then the others by decreasing number of boxes
    (ties in the trace's order). Channels without a sample are left out."""
    assert view.trace.images is not None
    samples, boxes = view.trace.images.samples, view.trace.images.boxes
    n = len(samples.channels)
    present = np.bincount(samples.channel, minlength=n) > 0
    counts = np.bincount(samples.channel[boxes.sample], minlength=n)
    asked = [] if view.query is None else list(view.query.options.get("channels") or [])
    first = [samples.channels.index(c) for c in dict.fromkeys(asked) if c in samples.channels]
    rest = [int(k) for k in np.argsort(-counts, kind="stable") if present[k] and int(k) not in first]
    return tuple(samples.channels[k] for k in first + rest if present[k])


def frame_positions(trace: LabelTrace) -> dict[int, int]:
    """The position (0..F-1) of every dataset frame index of the trace."""
    return {index: p for p, index in enumerate(trace.frame_index.tolist())}


def _match_view(trace: LabelTrace, positions: dict[int, int], row: Mapping[str, Any]) -> MatchView:
    try:
        first, last = positions[int(row["start_frame"])], positions[int(row["end_frame"])]
    except KeyError:
        raise UserError(
            f"match {row['match']} of {trace.name!r} names frames {row['start_frame']}-{row['end_frame']}, "
            "which the trace does not have (is it the trace these results were computed on?)"
        ) from None
    correspondence = row.get("correspondence") or {}
    if isinstance(correspondence, str):
        correspondence = json.loads(correspondence) if correspondence else {}
    known = set(trace.objects.id.tolist())
    missing = sorted(str(v) for v in correspondence.values() if str(v) not in known)
    if missing:
        raise UserError(f"match {row['match']} of {trace.name!r} names object {missing[0]!r}, not in the trace")
    return MatchView(
        int(row["match"]),
        first,
        last,
        {str(k): str(v) for k, v in correspondence.items()},
        row.get("explanation") or "",
    )


def crop_to_trace(road_map: RoadMap, trace: LabelTrace) -> RoadMap:
    """The map elements within :data:`MAP_MARGIN` of the box around the trace's positions."""
    x, y = trace.states.x, trace.states.y
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.any():
        return road_map
    x, y = x[finite], y[finite]
    cx, cy = (x.min() + x.max()) / 2, (y.min() + y.max()) / 2
    radius = float(np.hypot(x.max() - x.min(), y.max() - y.min())) / 2 + MAP_MARGIN
    return road_map.crop(float(cx), float(cy), radius)


def _marked(trace: LabelTrace, query: QueryInfo) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The observations (state rows, image boxes) of the classes a SpRE names, with its filters."""
    from ..spre import SearchOptions, compile_query
    from ..spre import syntax as s
    from ..spre.search import build_space

    compiled = compile_query(query.text, compat=bool(query.options.get("compat")))
    atoms = [node for node in compiled.tree.walk() if isinstance(node, s.ClassAtom)]
    channels = query.options.get("channels")
    options = SearchOptions(query.options.get("space"), None if channels is None else tuple(channels))
    try:
        space = build_space(trace, options, compiled.compat)
    except UserError:
        return None, None
    mask = np.zeros(len(space.category), dtype=bool)
    for atom in atoms:
        mask |= space.matches(atom)
    if space.kind == "topdown":
        return mask, None
    return None, _box_rows(trace, mask, options.channels)


def _box_rows(trace: LabelTrace, region_mask: np.ndarray, channels: tuple[str, ...] | None) -> np.ndarray:
    """A region mask of the image space (boxes of the kept channels) as a mask over all boxes."""
    from ..spre.space import channel_samples

    assert trace.images is not None
    samples, boxes = trace.images.samples, trace.images.boxes
    if channels is None:
        return region_mask
    kept = channel_samples(samples, channels)[boxes.sample]
    out = np.zeros(len(boxes), dtype=bool)
    out[kept] = region_mask
    return out
