"""RefAV's scenario-mining sequences (Argoverse 2): the data, its JSON form, and its pickle.

RefAV's scorer (``av2.evaluation.scenario_mining.eval``) reads a pickle of a dict keyed by
``(log_id, prompt)``; each value is the list of frames at the log's 2 Hz evaluation
timestamps. A frame holds ``timestamp_ns``, ``ego_translation_m`` (city x, y, z in metres) and,
per box, ``translation_m`` (N x 3, city, m), ``size`` (N x 3 length, width, height, m), ``yaw``
(N, radians, AV2's convention: 0 along +x, counter-clockwise), ``label`` (N; 0 = referred by the
prompt), ``track_id`` (N) and ``name`` (N, class names); ground truth may hold ``is_positive``
(True, False, or None: ambiguous), a temporal-only submission ``is_positive`` and no boxes.

scenegrep writes that pickle (:func:`write_pickle`: plain dicts, lists, tuples, numbers,
strings and numpy arrays it built itself) but never reads one: loading a pickle can run any
code its author put in it. It reads and writes the same data as JSON (:func:`write_json`,
:func:`read_sequences`)::

    {"format": "refav-scenario-mining", "sequences": [
      {"log_id": "...", "prompt": "...", "frames": [
        {"timestamp_ns": 315969904359876000, "ego_translation_m": [x, y, z],
         "translation_m": [[x, y, z], ...], "size": [[l, w, h], ...], "yaw": [...],
         "label": [0, ...], "track_id": ["...", ...], "name": ["...", ...],
         "is_positive": true}]}]}

Box arrays may be omitted when a frame has no box; ``is_positive`` may be omitted (then
``label`` says whether the frame is positive) or null (ambiguous).
"""

from __future__ import annotations

import math
import os
import pickle
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import orjson

from ..errors import UserError, at

FORMAT = "refav-scenario-mining"
"""The ``format`` value of scenegrep's RefAV JSON."""

REFERRED = 0
"""RefAV's label of a referred object (``SCENARIO_MINING_CATEGORIES.index('REFERRED_OBJECT')``)."""

MAX_BYTES = 1 << 30
"""Largest RefAV JSON file read (1 GiB), checked before reading."""

UNSET = "unset"
"""``RefFrame.is_positive`` of a frame that does not say (its labels decide)."""


@dataclass(frozen=True)
class RefFrame:
    """One frame at an evaluation timestamp (units and conventions: module docstring). Box arrays
    have one row per box; ``is_positive`` is True, False, None (ambiguous) or :data:`UNSET`."""

    timestamp_ns: int
    ego_translation_m: np.ndarray
    translation_m: np.ndarray
    size: np.ndarray
    yaw: np.ndarray
    label: np.ndarray
    track_id: np.ndarray
    name: np.ndarray
    is_positive: bool | None | str = UNSET

    def keep(self, mask: np.ndarray) -> RefFrame:
        """The frame with only the boxes where ``mask`` is True."""
        return RefFrame(
            self.timestamp_ns,
            self.ego_translation_m,
            self.translation_m[mask],
            self.size[mask],
            self.yaw[mask],
            self.label[mask],
            self.track_id[mask],
            self.name[mask],
            self.is_positive,
        )

    def as_refav(self) -> dict[str, Any]:
        """The frame as RefAV's scorer reads it (numpy arrays; every box scored 1)."""
        out: dict[str, Any] = {
            "timestamp_ns": int(self.timestamp_ns),
            "ego_translation_m": np.asarray(self.ego_translation_m, dtype=np.float64),
            "translation_m": self.translation_m.astype(np.float64).reshape(-1, 3),
            "size": self.size.astype(np.float32).reshape(-1, 3),
            "yaw": self.yaw.astype(np.float64),
            "label": self.label.astype(np.int32),
            "track_id": self.track_id.astype(str),
            "name": self.name.astype(str),
            "score": np.ones(len(self.label), dtype=np.float32),
        }
        if self.is_positive is not UNSET:
            out["is_positive"] = self.is_positive
        return out

    def as_json(self) -> dict[str, Any]:
        """The frame in scenegrep's RefAV JSON."""
        out: dict[str, Any] = {
            "timestamp_ns": int(self.timestamp_ns),
            "translation_m": self.translation_m.reshape(-1, 3).tolist(),
            "size": self.size.reshape(-1, 3).tolist(),
            "yaw": self.yaw.tolist(),
            "label": self.label.astype(int).tolist(),
            "track_id": self.track_id.astype(str).tolist(),
            "name": self.name.astype(str).tolist(),
        }
        if np.isfinite(self.ego_translation_m).all():
            out["ego_translation_m"] = self.ego_translation_m.tolist()
        if self.is_positive is not UNSET:
            out["is_positive"] = self.is_positive
        return out


Sequences = dict[tuple[str, str], list[RefFrame]]
"""(log id, prompt) -> its frames, in time order."""


def sequence_counts(sequences: Sequences) -> tuple[int, int, int]:
    """How many (log id, prompt) sequences there are, how many of them have a box in some frame,
    and how many frames (evaluation timestamps) they hold in all."""
    boxed = sum(any(len(frame.label) for frame in frames) for frames in sequences.values())
    return len(sequences), boxed, sum(len(frames) for frames in sequences.values())


def check_submission_path(path: str | Path) -> None:
    """UserError unless ``path`` ends in ``.pkl`` (RefAV's pickle) or ``.json`` (any case)."""
    if Path(path).suffix.lower() not in (".pkl", ".json"):
        raise UserError(f"--refav {path}: write a .pkl (RefAV's pickle) or a .json file")


def write_sequences(sequences: Sequences, path: str | Path) -> None:
    """Write ``sequences`` atomically: RefAV's pickle when ``path`` ends in ``.pkl``, JSON when it
    ends in ``.json`` (UserError for any other name: :func:`check_submission_path`)."""
    from ..writers.atomic import atomic_path

    check_submission_path(path)
    if Path(path).suffix.lower() == ".pkl":
        data = {key: [frame.as_refav() for frame in frames] for key, frames in sequences.items()}
        content = pickle.dumps(data, protocol=4)
    else:
        document = {
            "format": FORMAT,
            "sequences": [
                {"log_id": log_id, "prompt": prompt, "frames": [frame.as_json() for frame in frames]}
                for (log_id, prompt), frames in sequences.items()
            ],
        }
        content = orjson.dumps(document)
    with atomic_path(path) as tmp:
        tmp.write_bytes(content)


PICKLE_REFUSED = (
    "is a pickle, which can run code when loaded, so scenegrep does not read it; convert it to "
    "RefAV JSON in a Python you trust (README, 'scenegrep evaluate')"
)


def read_sequences(path: str | Path) -> Sequences:
    """The sequences of a RefAV JSON file (UserError, naming the place, for anything else: a
    pickle, a file over :data:`MAX_BYTES`, malformed JSON, a wrong type or shape, a number that
    is not finite, a (log id, prompt) given twice)."""
    path = Path(path)
    try:
        info = path.stat()
    except OSError as exc:
        raise UserError(f"cannot read: {exc.strerror}", at(path)) from None
    if not stat.S_ISREG(info.st_mode):
        raise UserError("not a regular file", at(path))
    if info.st_size > MAX_BYTES:
        raise UserError(f"{info.st_size} bytes is more than the {MAX_BYTES} bytes scenegrep reads", at(path))
    try:
        with open(path, "rb") as stream:
            content = stream.read(MAX_BYTES + 1)
    except OSError as exc:
        raise UserError(f"cannot read: {exc.strerror}", at(path)) from None
    if path.suffix.lower() in (".pkl", ".pickle") or content[:1] == b"\x80":
        raise UserError(PICKLE_REFUSED, at(path))
    try:
        document = orjson.loads(content)
    except orjson.JSONDecodeError as exc:
        raise UserError(f"not JSON: {exc}", at(path)) from None
    return _Reader(os.fspath(path)).document(document)


class _Reader:
    """Checks a decoded RefAV JSON document; errors name the file and the JSON path."""

    def __init__(self, origin: str):
        self.origin = origin

    def fail(self, where: str, what: str) -> UserError:
        return UserError(f"{self.origin}: {where}: {what}")

    def document(self, document: Any) -> Sequences:
        if not isinstance(document, dict) or document.get("format") != FORMAT:
            raise UserError(f'{self.origin}: not RefAV JSON (an object with "format": "{FORMAT}")')
        sequences = document.get("sequences")
        if not isinstance(sequences, list):
            raise self.fail("sequences", "must be a list")
        out: Sequences = {}
        for i, sequence in enumerate(sequences):
            where = f"sequences[{i}]"
            if not isinstance(sequence, dict):
                raise self.fail(where, "must be an object")
            key = (
                self.text(sequence.get("log_id"), f"{where}.log_id"),
                self.text(sequence.get("prompt"), f"{where}.prompt"),
            )
            if key in out:
                raise self.fail(where, f"log {key[0]!r} and prompt {key[1]!r} are given twice")
            frames = sequence.get("frames")
            if not isinstance(frames, list):
                raise self.fail(f"{where}.frames", "must be a list")
            out[key] = [self.frame(frame, f"{where}.frames[{j}]") for j, frame in enumerate(frames)]
        return out

    def text(self, value: Any, where: str) -> str:
        if not isinstance(value, str):
            raise self.fail(where, "must be a string")
        return value

    def frame(self, frame: Any, where: str) -> RefFrame:
        if not isinstance(frame, dict):
            raise self.fail(where, "must be an object")
        stamp = frame.get("timestamp_ns")
        if not isinstance(stamp, int) or isinstance(stamp, bool) or stamp < 0:
            raise self.fail(f"{where}.timestamp_ns", "must be a whole number of nanoseconds, not negative")
        label = frame.get("label", [])
        if not isinstance(label, list) or not all(
            isinstance(v, int) and not isinstance(v, bool) and -(2**63) <= v < 2**63 for v in label
        ):
            raise self.fail(f"{where}.label", "must be a list of whole numbers (64-bit)")
        n = len(label)
        ego = frame.get("ego_translation_m")
        ego_m = self.numbers(ego, 3, f"{where}.ego_translation_m") if ego is not None or n else np.full(3, np.nan)
        positive = frame.get("is_positive", UNSET)
        if positive is not UNSET and positive is not None and not isinstance(positive, bool):
            raise self.fail(f"{where}.is_positive", "must be true, false or null")
        return RefFrame(
            stamp,
            ego_m,
            self.rows(frame.get("translation_m", []), n, 3, f"{where}.translation_m"),
            self.rows(frame.get("size", []), n, 3, f"{where}.size"),
            self.numbers(frame.get("yaw", []), n, f"{where}.yaw"),
            np.array(label, dtype=np.int64),
            self.names(frame.get("track_id", []), n, f"{where}.track_id", ids=True),
            self.names(frame.get("name", [""] * n), n, f"{where}.name"),
            positive,
        )

    def numbers(self, value: Any, n: int, where: str) -> np.ndarray:
        ok = isinstance(value, list) and len(value) == n
        ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
        if not ok:
            raise self.fail(where, f"must be a list of {n} finite numbers")
        return np.array(value, dtype=np.float64)

    def rows(self, value: Any, n: int, width: int, where: str) -> np.ndarray:
        if not isinstance(value, list) or len(value) != n:
            raise self.fail(where, f"must be a list of {n} rows of {width} finite numbers (one per label)")
        return np.array([self.numbers(row, width, f"{where}[{k}]") for k, row in enumerate(value)]).reshape(n, width)

    def names(self, value: Any, n: int, where: str, ids: bool = False) -> np.ndarray:
        kinds = (str, int) if ids else (str,)
        if (
            not isinstance(value, list)
            or len(value) != n
            or not all(isinstance(v, kinds) and not isinstance(v, bool) for v in value)
        ):
            raise self.fail(where, f"must be a list of {n} {'ids' if ids else 'strings'} (one per label)")
        return np.array([str(v) for v in value], dtype=str).reshape(n)
