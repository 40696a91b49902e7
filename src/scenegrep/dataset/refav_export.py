"""A results table as a RefAV submission: per (AV2 log id, prompt), per 2 Hz evaluation
timestamp, the boxes of the tracks the prompt's referred object corresponds to.

- Logs: every trace of the table (with or without a match) must be an Argoverse 2 sensor log;
  its log id is the key. Failed traces and interrupted runs are refused: their answers are
  unknown, and RefAV would score them as negatives.
- Evaluation timestamps: every 5th annotation timestamp of the log from the first (RefAV's 2 Hz
  subsampling of the 10 Hz annotations), as nanoseconds: the log's first timestamp plus the
  frame's time.
- Referred object: the program object ``referred`` names, else the one program object that is
  not ``ego`` (an error when there are several or none: RefAV's prompts refer to one object).
- At a timestamp, a match contributes its referred object's track when the timestamp's frame is
  among the frames that object is involved in (the ``objects`` column) and the object is
  observed there: its centre (city x, y, z, m), size (length, width, height, m), yaw (AV2's
  convention) and class, labelled 0 (referred).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError
from ..model import LabelTrace
from ..model.geometry import yaw_from_heading
from .refav_format import REFERRED, RefFrame, Sequences, check_submission_path
from .results import Results

AV2_SENSOR = "argoverse2-sensor"
"""The ``dataset`` attribute of traces read from Argoverse 2 sensor logs."""

EVALUATION_STRIDE = 5
"""RefAV evaluates every 5th frame of a 10 Hz log (2 Hz)."""


def check_request(path: str | Path, prompt: str | None) -> None:
    """The checks of a submission request before any result is read: ``path`` names a ``.pkl`` or
    ``.json`` file (:func:`scenegrep.dataset.refav_format.check_submission_path`) and ``prompt`` is
    not empty; UserError otherwise."""
    check_submission_path(path)
    check_prompt(prompt)


def check_prompt(prompt: str | None) -> None:
    """UserError for no prompt or an empty one (RefAV keys a submission by log id and prompt)."""
    if not prompt:
        raise UserError("--refav needs --prompt TEXT: RefAV keys a submission by (log id, prompt)")


def refav_sequences(
    results: Results, load: Callable[[str], LabelTrace], prompt: str, referred: str | None = None
) -> Sequences:
    """The RefAV sequences of ``results`` for ``prompt`` (module docstring); ``load`` gives a
    trace of the table by trace id. UserError for what RefAV cannot be given (an empty prompt
    first: :func:`check_request`)."""
    check_prompt(prompt)
    if results.status != "finished":
        raise UserError(f"the run is {results.status}: its results are partial, so a RefAV submission would be wrong")
    rows = results.table.to_pylist()
    failed = [r for r in rows if r["status"] == "failed"]
    if failed:
        raise UserError(f"trace {failed[0]['name']} failed, so its answer is unknown; rerun the query before exporting")
    sequences: Sequences = {}
    for trace_id in dict.fromkeys(r["trace_id"] for r in rows):
        trace = load(trace_id)
        log_id = _log_id(trace)
        if (log_id, prompt) in sequences:
            raise UserError(f"log {log_id} is in the results twice")
        matches = [r for r in rows if r["trace_id"] == trace_id and r["status"] == "match"]
        sequences[(log_id, prompt)] = _frames(trace, [_referred_span(r, referred) for r in matches])
    return sequences


def _log_id(trace: LabelTrace) -> str:
    """The AV2 log id of a trace read from an AV2 sensor log (UserError for another dataset)."""
    if trace.attributes.get("dataset") != AV2_SENSOR or not trace.attributes.get("log_id"):
        raise UserError(
            f"trace {trace.name} is not an Argoverse 2 sensor log; RefAV scores AV2 logs by log id and timestamp"
        )
    return str(trace.attributes["log_id"])


def _referred_span(row: dict[str, Any], referred: str | None) -> tuple[str, int, int]:
    """(track id, first and last dataset frame index) of a match row's referred object."""
    try:
        objects = json.loads(row["objects"]) if row["objects"] else _objects_of_old_row(row)
        name = _referred_name(row, objects, referred)
        found = objects[name]
        return str(found["id"]), int(found["start_frame"]), int(found["end_frame"])
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise UserError(f"match {row['match']} of {row['name']}: its objects are not scenegrep's ({exc})") from None


def _referred_name(row: dict[str, Any], objects: dict[str, Any], referred: str | None) -> str:
    """The program object of a match that the prompt refers to (module docstring)."""
    if referred is not None:
        if referred not in objects:
            raise UserError(
                f"--referred {referred}: match {row['match']} of {row['name']} has no such program object "
                f"(it has {', '.join(objects) or 'none'})"
            )
        return referred
    others = [n for n in objects if n != "ego"]
    if len(others) != 1:
        raise UserError(
            f"the query's objects besides ego are {', '.join(others) or 'none'}: name the one the prompt refers "
            "to with --referred NAME"
        )
    return others[0]


def _objects_of_old_row(row: dict[str, Any]) -> dict[str, Any]:
    """The ``objects`` of a row from a table written before that column: each program object is
    involved in the whole match."""
    correspondence = json.loads(row["correspondence"] or "{}")
    return {
        n: {"id": i, "start_frame": row["start_frame"], "end_frame": row["end_frame"]}
        for n, i in correspondence.items()
    }


def _frames(trace: LabelTrace, spans: list[tuple[str, int, int]]) -> list[RefFrame]:
    """The trace's frames at the evaluation timestamps, with the referred tracks' boxes."""
    origin = int(trace.attributes.get("time_origin_ns", 0))
    positions = np.arange(0, trace.n_frames, EVALUATION_STRIDE)
    rows = {(int(f), int(o)): k for k, (f, o) in enumerate(zip(trace.states.frame, trace.states.object))}
    ids = trace.objects.row_of()
    ego = ids[trace.ego] if trace.ego is not None else -1
    states = trace.states
    unknown = sorted({t for t, _, _ in spans} - set(ids))
    if unknown:
        raise UserError(
            f"trace {trace.name} has no object {unknown[0]!r} that the results name; were they computed on it?"
        )
    frames = []
    for position in positions.tolist():
        index = int(trace.frame_index[position])
        stamp = origin + int(round(float(trace.frame_time[position]) * 1e9))
        ego_row = rows.get((position, ego))
        if ego_row is None:
            raise UserError(f"trace {trace.name}: the ego has no pose at frame {index}")
        ego_m = np.array([states.x[ego_row], states.y[ego_row], states.z[ego_row]])
        tracks = sorted({t for t, first, last in spans if first <= index <= last})
        found = [rows[(position, ids[t])] for t in tracks if (position, ids[t]) in rows]
        k = np.array(found, dtype=np.int64)
        frames.append(
            RefFrame(
                stamp,
                ego_m,
                np.stack([states.x[k], states.y[k], states.z[k]], axis=1),
                np.stack([states.length[k], states.width[k], states.height[k]], axis=1),
                yaw_from_heading(states.heading[k]),
                np.full(len(k), REFERRED, dtype=np.int64),
                trace.objects.id[states.object[k]].astype(str),
                trace.objects.category[states.object[k]].astype(str),
            )
        )
    return frames
