"""A match as a moment to re-simulate: the labeled objects over the match's window, with their
paths, for the exporters to Scenic and OpenSCENARIO.

A :class:`Moment` holds, for one match row of a results table, every program object's labeled
object (its correspondence) and, with ``context`` metres, every other labeled object whose
centre is within that distance of a corresponded object in some frame of the window. Each
object's :class:`ObjectPath` lists its observations over the window in frame order: times in
seconds from the window's first frame, map-frame positions (m), headings (rad, Scenic's
convention: 0 along +y, counter-clockwise) and its size (m, the median of its observations in
the window). Objects are ordered: the ego first when the trace has one, then the corresponded
objects in the correspondence's order, then context objects by label id.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError
from ..model import LabelTrace
from ..model.trace import MapSource
from ..wording import counted
from .results import Results

MAX_CONTEXT_M = 1000.0
"""The largest ``context`` radius (m) a user may ask for."""


@dataclass(frozen=True, eq=False)
class ObjectPath:
    """One labeled object over a moment's window (units in the module docstring); ``program_name``
    is the program object it corresponds to (None for a context object)."""

    label_id: str
    program_name: str | None
    category: str
    length: float
    width: float
    height: float
    times: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    heading: np.ndarray


@dataclass(frozen=True, eq=False)
class Moment:
    """One match (row ``match`` of trace ``trace_name``) as objects over its window of dataset
    frames ``start_frame``..``end_frame`` (inclusive), starting ``start_time`` s into the trace and
    lasting ``duration`` s (first to last frame; 0 for one frame); ``frame_period`` is the trace's
    frame period (s, the median step of its known frame times; 0.1 with fewer than two);
    ``map_source`` is where the trace's road map is read (None: the trace has none); ``ego`` is the
    ego's label id when the trace names one."""

    trace_id: str
    trace_name: str
    match: int
    start_frame: int
    end_frame: int
    start_time: float
    map_source: MapSource | None
    ego: str | None
    objects: tuple[ObjectPath, ...]
    duration: float = 0.0
    frame_period: float = 0.1


def check_output_folder(folder: str | Path, option: str) -> None:
    """The folder an exporter of moments writes one file per match into, checked before anything
    is read: UserError (naming ``option``, e.g. ``--scenic``) for an empty or blank name, or a path
    that exists and is not a directory."""
    if not str(folder).strip():
        raise UserError(f"{option}: give the folder to write to")
    if Path(folder).exists() and not Path(folder).is_dir():
        raise UserError(f"{option} {folder}: not a directory (one file per match is written into a directory)")


def left_out(results: Results, name: str) -> list[str]:
    """What an export of the moments of ``results`` (called ``name`` in the text, e.g. its file)
    cannot hold, one sentence each: the failed traces (their matches are unknown) and, for an
    interrupted run, the traces it did not reach. Empty when nothing is left out."""
    failed = results.counts()["failed"]
    said = [f"{counted(failed, 'trace')} failed in {name}: their matches are unknown, none exported"] if failed else []
    if results.status == "interrupted":
        said.append(f"{name} is an interrupted run: the traces it did not reach are not exported")
    return said


def moments(results: Results, load: Callable[[str], LabelTrace], context: float | None = None) -> Iterator[Moment]:
    """The moments of every match row of ``results`` in table order; ``load`` gives a trace by
    trace id; ``context`` (m, 0..:data:`MAX_CONTEXT_M`) adds nearby labeled objects. Rows that are
    not matches (failed, pruned, without a match) have no moment. UserError for a radius out of
    range and for rows that do not fit their trace (see :func:`moment_of`)."""
    if context is not None and not 0 <= context <= MAX_CONTEXT_M:
        raise UserError(f"--context {context}: give a radius from 0 to {MAX_CONTEXT_M:g} m")
    rows = [r for r in results.table.to_pylist() if r["status"] == "match"]
    loaded: tuple[str, LabelTrace] | None = None
    for row in rows:
        if loaded is None or loaded[0] != row["trace_id"]:
            loaded = (row["trace_id"], load(row["trace_id"]))
        yield moment_of(loaded[1], row, context)


def moment_of(trace: LabelTrace, row: dict[str, Any], context: float | None = None) -> Moment:
    """The moment of one match row over ``trace`` (see :func:`moments`). UserError for a
    correspondence that is not scenegrep's JSON, an object the trace does not have or that is not
    observed in the window, a window outside the trace or with frames of unknown time."""
    correspondence = _correspondence(row)
    positions = _window(trace, row)
    times = trace.frame_time[positions]
    if np.isnan(times).any():
        raise UserError(f"match {row['match']} of {trace.name}: the trace gives no time for some frames of its window")
    ids = trace.objects.row_of()
    missing = sorted(set(correspondence.values()) - set(ids))
    if missing:
        raise UserError(f"trace {trace.name} has no object {missing[0]!r} that match {row['match']} names")
    names = {label: name for name, label in correspondence.items()}
    chosen = list(dict.fromkeys(([trace.ego] if trace.ego in ids else []) + list(correspondence.values())))
    in_window = np.isin(trace.states.frame, positions)
    if context is not None:
        chosen += _nearby(trace, in_window, [ids[c] for c in chosen], context)
    objects = tuple(_path(trace, in_window, ids[label], label, names.get(label), positions[0]) for label in chosen)
    return Moment(
        trace_id=str(row["trace_id"]),
        trace_name=str(row["name"]),
        match=int(row["match"]),
        start_frame=int(row["start_frame"]),
        end_frame=int(row["end_frame"]),
        start_time=float(times[0]),
        duration=float(times[-1] - times[0]),
        frame_period=_frame_period(trace.frame_time),
        map_source=trace.map_source,
        ego=trace.ego if trace.ego in ids else None,
        objects=objects,
    )


def _correspondence(row: dict[str, Any]) -> dict[str, str]:
    try:
        found = json.loads(row["correspondence"] or "{}")
        return {str(name): str(label) for name, label in found.items()}
    except (ValueError, AttributeError):
        raise UserError(f"match {row['match']} of {row['name']}: its correspondence is not scenegrep's") from None


def _window(trace: LabelTrace, row: dict[str, Any]) -> np.ndarray:
    """The frame positions of a row's window (its dataset frame indices ``start_frame``..``end_frame``)."""
    index = trace.frame_index
    positions = np.flatnonzero((index >= int(row["start_frame"])) & (index <= int(row["end_frame"])))
    if not len(positions):
        raise UserError(
            f"match {row['match']} of {trace.name}: frames {row['start_frame']}..{row['end_frame']} "
            "are not in the trace"
        )
    return positions


def _nearby(trace: LabelTrace, in_window: np.ndarray, anchors: list[int], radius: float) -> list[str]:
    """Label ids of the objects besides ``anchors`` whose centre comes within ``radius`` m of an
    anchor's centre in a frame of the window, sorted."""
    states = trace.states
    rows = np.flatnonzero(in_window)
    frame, obj = states.frame[rows], states.object[rows]
    anchor_rows = np.flatnonzero(np.isin(obj, anchors))
    # states are in (frame, object) order: each anchor observation's frame is one run of rows
    start = np.searchsorted(frame, frame[anchor_rows], side="left")
    stop = np.searchsorted(frame, frame[anchor_rows], side="right")
    counts = stop - start
    anchor = np.repeat(anchor_rows, counts)
    other = np.repeat(start - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
    gap = np.hypot(states.x[rows[other]] - states.x[rows[anchor]], states.y[rows[other]] - states.y[rows[anchor]])
    near = np.unique(obj[other][(gap <= radius) & ~np.isin(obj[other], anchors)])
    return sorted(str(trace.objects.id[o]) for o in near.tolist())


def _path(trace: LabelTrace, in_window: np.ndarray, row: int, label: str, name: str | None, first: int) -> ObjectPath:
    states = trace.states
    k = np.flatnonzero(in_window & (states.object == row))
    if not len(k):
        raise UserError(f"trace {trace.name}: object {label} is not observed in the match's window")
    return ObjectPath(
        label_id=label,
        program_name=name,
        category=str(trace.objects.category[row]),
        length=_median(states.length[k]),
        width=_median(states.width[k]),
        height=_median(states.height[k]),
        times=trace.frame_time[states.frame[k]] - trace.frame_time[first],
        x=states.x[k].copy(),
        y=states.y[k].copy(),
        z=states.z[k].copy(),
        heading=states.heading[k].copy(),
    )


def _frame_period(frame_time: np.ndarray) -> float:
    """The median step (s) of the known (not NaN) frame times; 0.1 with fewer than two."""
    steps = np.diff(frame_time[~np.isnan(frame_time)])
    return float(np.median(steps)) if len(steps) else 0.1


def _median(values: np.ndarray) -> float:
    """The median of the finite values (NaN when there are none)."""
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if len(finite) else float("nan")
