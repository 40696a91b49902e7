"""The per-user cache directory (derived data that is slow to rebuild, e.g. converted maps)."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

CACHE_ENV = "SCENEGREP_CACHE"


def cache_dir() -> Path:
    """``$SCENEGREP_CACHE``, else ``$XDG_CACHE_HOME/scenegrep``, else ``~/.cache/scenegrep``."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "scenegrep"


def file_digest(path: str | Path) -> str:
    """Hex SHA-256 of a file's content."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
