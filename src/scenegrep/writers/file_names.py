"""Names of the files scenegrep writes from names in the data (trace names and ids, object ids)."""

from __future__ import annotations

import re

_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")


def file_stem(text: str, limit: int = 100, fallback: str = "trace") -> str:
    """``text`` as a file name part that stays inside its folder: every run of characters other
    than letters, digits, ``.``, ``_`` and ``-`` becomes one ``_``, leading and trailing dots and
    underscores are dropped (no hidden files, no ``..``), at most ``limit`` characters; ``fallback``
    when nothing is left."""
    return _UNSAFE.sub("_", text).strip("._")[:limit] or fallback
