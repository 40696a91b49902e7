"""RefAV's classification metrics: timestamp-level and log-level balanced accuracy.

As RefAV's scorer computes them (``compute_temporal_metrics`` of
``av2.evaluation.scenario_mining.eval``), without torch:

- A submission *tracks* when some predicted frame has no ``is_positive`` or has track ids; then
  both sides lose the boxes whose centre is more than ``max_range_m`` (50 m, xy) from the ego
  and, when a drivable area is given per log, the boxes none of whose four corners lies within
  5 m of it (:func:`filter_boxes`). A temporal-only submission is not filtered.
- A ground-truth frame with ``is_positive`` is positive, negative or (None) ambiguous as it says;
  one without is positive when a referred box (label 0) is left. A predicted frame is positive
  when its ``is_positive`` is true or a referred box is left (whatever ``is_positive`` says).
- Per prompt, over its (log, prompt) pairs: TP/FP/FN/TN over the non-ambiguous frames
  (timestamp level), and one count per pair (log level: positive in ground truth when a
  non-ambiguous frame is, predicted positive when any predicted frame is). A pair whose frames
  are all ambiguous adds nothing, but its prompt is still scored (1.0 when nothing counts).
- Balanced accuracy = (TP / (TP + FN) + TN / (TN + FP)) / 2, a zero denominator giving 1.0; the
  headline is the unweighted mean over prompts.

Frames are paired by position, as RefAV does; scenegrep also requires the two sides' timestamps
to be equal, so a misaligned submission is an error instead of a wrong score.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from ..errors import UserError
from ..model.geometry import box_corners, heading_from_yaw
from .refav_format import REFERRED, UNSET, RefFrame, Sequences, read_sequences

MAX_RANGE_M = 50.0
"""RefAV's evaluation range: boxes farther (xy, m) from the ego are not evaluated."""

ROI_DILATION_M = 5.0
"""RefAV's region of interest: the drivable area dilated by this many metres."""


@dataclass
class Counts:
    """A confusion matrix of binary decisions."""

    tp: int = 0
    fp: int = 0
    fn: int = 0
    tn: int = 0

    def add(self, truth: np.ndarray, predicted: np.ndarray) -> None:
        """Count decisions (boolean arrays of equal length)."""
        self.tp += int(np.sum(truth & predicted))
        self.fp += int(np.sum(~truth & predicted))
        self.fn += int(np.sum(truth & ~predicted))
        self.tn += int(np.sum(~truth & ~predicted))

    def balanced_accuracy(self) -> float:
        """(TPR + TNR) / 2, a rate with a zero denominator counting 1.0."""
        tpr = self.tp / (self.tp + self.fn) if self.tp + self.fn else 1.0
        tnr = self.tn / (self.tn + self.fp) if self.tn + self.fp else 1.0
        return (tpr + tnr) / 2


@dataclass
class PromptScore:
    """One prompt's counts at both levels."""

    prompt: str
    timestamp: Counts = field(default_factory=Counts)
    log: Counts = field(default_factory=Counts)


@dataclass(frozen=True)
class Evaluation:
    """The scores: per prompt (ground-truth order), their means, whether the boxes were filtered
    (a tracking submission), how many predicted pairs the ground truth does not have, the
    evaluation range (m) and whether a drivable area was given."""

    prompts: list[PromptScore]
    filtered: bool
    unscored_pairs: int
    max_range_m: float = MAX_RANGE_M
    drivable_area: bool = False

    @property
    def timestamp_ba(self) -> float:
        return float(np.mean([p.timestamp.balanced_accuracy() for p in self.prompts])) if self.prompts else 1.0

    @property
    def log_ba(self) -> float:
        return float(np.mean([p.log.balanced_accuracy() for p in self.prompts])) if self.prompts else 1.0

    def document(self) -> dict[str, Any]:
        """The scores as one JSON-able record (what ``scenegrep evaluate --json`` prints): both mean
        balanced accuracies, each prompt's ``timestamp`` and ``log`` counts with their balanced
        accuracy, ``boxes_filtered``, ``max_range_m``, ``drivable_area_filter`` (the boxes were
        filtered by a drivable area) and ``unscored_prediction_pairs``."""
        return {
            "timestamp_balanced_accuracy": self.timestamp_ba,
            "log_balanced_accuracy": self.log_ba,
            "prompts": [
                {"prompt": p.prompt, **{level: _counts(getattr(p, level)) for level in ("timestamp", "log")}}
                for p in self.prompts
            ],
            "boxes_filtered": self.filtered,
            "max_range_m": self.max_range_m,
            "drivable_area_filter": self.filtered and self.drivable_area,
            "unscored_prediction_pairs": self.unscored_pairs,
        }


def _counts(counts: Counts) -> dict[str, Any]:
    return {
        "balanced_accuracy": counts.balanced_accuracy(),
        "tp": counts.tp,
        "fp": counts.fp,
        "fn": counts.fn,
        "tn": counts.tn,
    }


Region = Callable[[str], shapely.Geometry]
"""Log id -> its drivable area (map frame, m)."""


def filter_boxes(frame: RefFrame, max_range_m: float, drivable: shapely.Geometry | None) -> RefFrame:
    """The frame without the boxes RefAV does not evaluate: centre farther than ``max_range_m``
    (xy) from the ego, or (with a ``drivable`` area) no corner within 5 m of it. RefAV rasterises
    the dilated area at 0.1 m; this measures the distance exactly."""
    if len(frame.label) == 0:
        return frame
    keep = np.hypot(*(frame.translation_m[:, :2] - frame.ego_translation_m[:2]).T) <= max_range_m
    if drivable is not None:
        x, y = frame.translation_m[:, 0], frame.translation_m[:, 1]
        corners = box_corners(x, y, heading_from_yaw(frame.yaw), frame.size[:, 0], frame.size[:, 1])
        near = shapely.dwithin(drivable, shapely.points(corners.reshape(-1, 2)), ROI_DILATION_M)
        keep &= near.reshape(len(x), -1).any(axis=1)
    return frame.keep(keep)


def evaluate(
    predictions: Sequences, truth: Sequences, max_range_m: float = MAX_RANGE_M, drivable: Region | None = None
) -> Evaluation:
    """RefAV's balanced accuracies of ``predictions`` against ``truth`` (module docstring).
    UserError when ``max_range_m`` is not a positive number, a ground-truth pair has no
    prediction or its frames' timestamps differ."""
    check_max_range(max_range_m)
    tracking = any(f.is_positive is UNSET or len(f.track_id) for fs in predictions.values() for f in fs)
    scores: dict[str, PromptScore] = {}
    for key, frames in truth.items():
        log_id, prompt = key
        score = scores.setdefault(prompt, PromptScore(prompt))
        predicted = predictions.get(key)
        if predicted is None:
            raise UserError(f"the predictions have no frames for log {log_id!r} and prompt {prompt!r}")
        if [f.timestamp_ns for f in predicted] != [f.timestamp_ns for f in frames]:
            raise UserError(
                f"log {log_id!r}, prompt {prompt!r}: the predicted frames' timestamps are not the ground truth's "
                f"({len(predicted)} and {len(frames)} frames; RefAV pairs frames by position)"
            )
        if tracking:
            area = drivable(log_id) if drivable is not None else None
            frames = [filter_boxes(f, max_range_m, area) for f in frames]
            predicted = [filter_boxes(f, max_range_m, area) for f in predicted]
        _count(score, frames, predicted)
    unscored = len(set(predictions) - set(truth))
    return Evaluation(list(scores.values()), tracking, unscored, max_range_m, drivable is not None)


def check_max_range(max_range_m: float) -> None:
    """UserError unless ``max_range_m`` is a finite positive number (of metres)."""
    if not (math.isfinite(max_range_m) and max_range_m > 0):
        raise UserError(f"--max-range {max_range_m}: give a positive number of metres")


def evaluate_files(
    predictions: str | Path, truth: str | Path, max_range_m: float = MAX_RANGE_M, av2: str | Path | None = None
) -> Evaluation:
    """:func:`evaluate` on two RefAV JSON files (:func:`scenegrep.dataset.refav_format.read_sequences`:
    UserError for a pickle, a missing or malformed file), with the drivable areas of the AV2 sensor
    split ``av2`` (:func:`av2_drivable_areas`) when given; ``max_range_m`` is checked first."""
    check_max_range(max_range_m)
    drivable = av2_drivable_areas(av2) if av2 is not None else None
    return evaluate(read_sequences(predictions), read_sequences(truth), max_range_m, drivable)


def _count(score: PromptScore, frames: list[RefFrame], predicted: list[RefFrame]) -> None:
    """Add one (log, prompt) pair's frames to its prompt's counts."""
    ambiguous = np.array([f.is_positive is None for f in frames], dtype=bool)
    if ambiguous.all():
        return
    truth = np.array([_positive(f) for f in frames], dtype=bool)
    guess = np.array([f.is_positive is True or bool(np.any(f.label == REFERRED)) for f in predicted], dtype=bool)
    score.timestamp.add(truth[~ambiguous], guess[~ambiguous])
    score.log.add(np.array([truth[~ambiguous].any()]), np.array([guess.any()]))


def _positive(frame: RefFrame) -> bool:
    """A frame's own answer: its ``is_positive`` when it gives one, else whether it has a referred box."""
    if frame.is_positive is UNSET:
        return bool(np.any(frame.label == REFERRED))
    return frame.is_positive is True


def av2_drivable_areas(root: str | Path) -> Region:
    """Log id -> the drivable area of the map of the AV2 log ``root/<log id>/`` (RefAV's
    ``--dataset_dir``: a sensor split such as ``val/``), read once per log; UserError when the
    log or its map is missing or the map has no drivable area."""
    from ..readers import read_map
    from ..readers.av2_map import find_map

    found: dict[str, shapely.Geometry] = {}

    def drivable(log_id: str) -> shapely.Geometry:
        if log_id not in found:
            folder = Path(root) / log_id
            map_path = find_map(folder) if folder.is_dir() and log_id not in ("", ".", "..") else None
            if map_path is None:
                raise UserError(f"--av2 {root}: no Argoverse 2 log {log_id!r} with a map in it")
            area = read_map(map_path).drivable_area
            if area is None or area.is_empty:
                raise UserError(f"{map_path}: the map has no drivable area")
            shapely.prepare(area)
            found[log_id] = area
        return found[log_id]

    return drivable
