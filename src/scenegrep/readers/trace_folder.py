"""A folder of trace files (a dataset written by ``scenegrep synth`` or ``scenegrep label``, say).

Every file directly in the folder whose format holds label traces is read, in name order; other
files (a manifest, a README, maps) are skipped, and so are JSON files that are not scenegrep
traces (STREM streams are recognised by weak signs only: give them by name). Sub-folders are not
entered.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from ..errors import UserError, at
from ..model import LabelTrace

SKIPPED = frozenset({"strem-json"})
"""Formats not collected from a folder (see the module docstring)."""


def trace_files(path: str | Path) -> list[Path]:
    """The files of the folder that hold label traces, in name order."""
    from . import FORMATS, sniff_file

    found = []
    for child in sorted(Path(path).iterdir()):
        name = sniff_file(child) if child.is_file() else None
        if name is not None and name not in SKIPPED and FORMATS[name].traces:
            found.append(child)
    return found


def read_traces(path: str | Path) -> Iterator[LabelTrace]:
    """Every trace of every trace file in the folder."""
    from . import read_traces as read_file

    files = trace_files(path)
    if not files:
        raise UserError("a folder without trace files", at(path))
    for child in files:
        yield from read_file(child)
