"""Converted road maps cached as scenegrep Parquet maps in the user cache (:func:`~scenegrep.cache.cache_dir`).

A map file that is slow to convert (OpenDRIVE through Scenic, a city's Lanelet2 map) is converted
once per content: the cache file is named by the SHA-256 of the source file and a ``tag`` naming
the converter and its version (bumped whenever a conversion changes), so a later load reads the
Parquet map in a fraction of the time. The cache is best effort: when it cannot be written the
converted map is still returned.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from ..cache import cache_dir, file_digest
from ..errors import UserError
from ..model import RoadMap
from ..writers.trace_parquet import write_map_parquet
from .trace_parquet import read_map as read_cached


def cached_map_path(path: Path, tag: str) -> Path:
    """Where the converted map of the file at ``path`` is cached."""
    return cache_dir() / "maps" / f"{file_digest(path)[:20]}-{tag}.map.parquet"


def through_cache(path: Path, tag: str, convert: Callable[[], RoadMap]) -> RoadMap:
    """The map of ``path`` from the cache, else ``convert()``'s, then cached; named after ``path``
    (its stem and path) whichever file of the same content was converted first."""
    cached = cached_map_path(path, tag)
    if cached.is_file():
        return replace(read_cached(cached), name=path.stem, source=str(path))
    road_map = convert()
    with contextlib.suppress(OSError, UserError):  # the writer's "cannot write" (read-only cache)
        write_map_parquet(road_map, cached)
    return road_map
