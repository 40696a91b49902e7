"""How every query command names a match in its text lines: ``SOURCE#NAME:START-END``.

``SOURCE`` is the input path as the user gave it (relative stays relative; a file found in a
given directory is that directory's path joined with the file's path under it), for a
``--dataset`` run the source path the catalog records, ``-`` for standard input; ``NAME`` is the
trace's name; ``START`` and ``END`` are the dataset frame indices of the match's first and last
frame (inclusive). ``show --trace`` accepts each such place (:mod:`scenegrep.view.trace_names`).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from pathlib import Path


def place(source: str, name: str, first: int | None = None, last: int | None = None) -> str:
    """``SOURCE#NAME:FIRST-LAST``, or ``SOURCE#NAME`` without frames (a trace without a match)."""
    trace = f"{source}#{name}"
    return trace if first is None or last is None else f"{trace}:{first}-{last}"


def as_given(paths: Iterable[str]) -> Callable[[str], str]:
    """A function from a recorded source (an absolute, resolved path, as a query over files
    records it) to that path as the user gave it among ``paths``: the given path itself, or a given
    directory's path joined with the source's path under it. A source under no given path (a
    symbolic link in a directory that leads out of it) stays as recorded."""
    given = [(path, _resolved(path)) for path in paths if path != "-"]

    def shown(source: str) -> str:
        recorded = Path(source)
        for path, resolved in given:
            if resolved is None:
                continue
            if recorded == resolved:
                return path
            if recorded.is_relative_to(resolved):
                return os.path.join(path, recorded.relative_to(resolved))
        return source

    return shown


def _resolved(path: str) -> Path | None:
    try:
        return Path(path).resolve()
    except (OSError, RuntimeError, ValueError):
        return None
