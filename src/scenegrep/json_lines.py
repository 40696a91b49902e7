"""JSON Lines: the one writer of every command's ``--json`` output.

Each record is one JSON object on one line. Numbers are written at the data's precision, never
with binary floating-point noise (``0.30000000000000004``):

- integers, strings, booleans and null as they are; NaN (unknown) as ``NaN``, as Python's
  ``json`` and the results readers read it;
- a float under a key that names a time or a duration in seconds (``time``, ``*_time``,
  ``*_s``) is rounded to 9 decimals, 1 ns: the finest timestamp any reader gives;
- every other float (metres, radians, m/s, Hz, scores) is rounded to 6 decimals: 1 µm, 1 µrad;
- a rounded float is written as the shortest decimal that reads back as it (``repr``), so
  ``0.1 + 0.2`` is written ``0.3`` and ``14.9`` stays ``14.9``.

A list inherits the key it is under; the keys of a nested object apply to their own values.
"""

from __future__ import annotations

import json
import math
import sys
from typing import Any, TextIO

TIME_DECIMALS = 9
"""Decimals of a time or duration in seconds: 1 ns."""

OTHER_DECIMALS = 6
"""Decimals of every other float: 1 µm, 1 µrad, 1e-6 of any other unit."""


def is_time_key(key: str | None) -> bool:
    """Whether a float under ``key`` is a time or duration in seconds."""
    return key is not None and (key == "time" or key.endswith("_time") or key.endswith("_s"))


def rounded(value: Any, key: str | None = None) -> Any:
    """``value`` with every float rounded by the module's rule (``key``: the key it is under)."""
    if isinstance(value, float):
        if not math.isfinite(value):
            return value
        return round(value, TIME_DECIMALS if is_time_key(key) else OTHER_DECIMALS) + 0.0  # no -0.0
    if isinstance(value, dict):
        return {k: rounded(v, str(k)) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [rounded(v, key) for v in value]
    return value


def line(record: Any) -> str:
    """One JSON Lines record (without its newline), numbers rounded (see the module docstring)."""
    return json.dumps(rounded(record), allow_nan=True)


def write(record: Any, stream: TextIO | None = None) -> None:
    """Write one record and its newline to ``stream`` (standard output by default)."""
    (stream or sys.stdout).write(line(record) + "\n")
