"""``--map MAP``: the road map of traces that name none of their own.

One rule for ``ingest`` and the query commands over files (``scene``, ``scenario``, ``coverage``)
and ``label``: a trace without a map of its own takes ``MAP``; a trace that names its own map
and a ``--map`` is a user error for that trace (a ``failed`` row, or the command's error when it
is the only trace), never a silent choice of one of the two maps: which map is meant is the
user's to say (query such a trace without ``--map``, or rewrite its map entry). ``MAP`` is named
by its absolute path, so a dataset that ingested it reads it from anywhere.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..errors import UserError, at
from ..model import LabelTrace, MapSource
from . import FORMATS, detect_format


def given_map_source(path: str) -> MapSource:
    """``path`` as a map source: a regular file of a map format (UserError otherwise)."""
    name = detect_format(path)
    if not FORMATS[name].map:
        raise UserError(f"--map: a {FORMATS[name].description} holds no road map", at(path))
    return MapSource(str(Path(path).resolve()), name)


def conflict(name: str, own_map: str) -> UserError:
    """The error of a trace ``name`` that has its own map ``own_map`` and is given a ``--map``."""
    return UserError(
        f"trace {name!r} has its own road map ({Path(own_map).name}) and --map gives another; "
        "--map is for traces without a map: leave it out for this trace"
    )


def with_given_map(trace: LabelTrace, map_path: str | None) -> LabelTrace:
    """``trace`` with the map ``map_path`` when it names none; unchanged without ``map_path``;
    a UserError when it names its own map too."""
    if map_path is None:
        return trace
    if trace.map_source is not None:
        raise conflict(trace.name, trace.map_source.path)
    return replace(trace, map_source=given_map_source(map_path))
