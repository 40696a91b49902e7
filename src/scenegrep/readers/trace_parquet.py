"""scenegrep's Parquet trace and map files (layouts in :mod:`scenegrep.model.trace_arrow`
and :mod:`scenegrep.model.map_arrow`)."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TypeVar

import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import UserError, at
from ..model import LabelTrace, RoadMap
from ..model.map_arrow import is_map_table, map_from_table
from ..model.trace_arrow import is_trace_table, trace_from_table
from .common import reading

FORMAT = "scenegrep-parquet"
MAP_FORMAT = "scenegrep-map-parquet"
T = TypeVar("T")


def kind(path: str | Path) -> str | None:
    """``trace`` or ``map`` for a scenegrep Parquet file, None for any other Parquet file."""
    with reading(path, "Parquet file", pa.ArrowException):
        schema = pq.read_schema(path)
    if is_trace_table(schema):
        return "trace"
    return "map" if is_map_table(schema) else None


def _read(path: str | Path, what: str, is_kind: Callable[[pa.Schema], bool], convert: Callable[[pa.Table], T]) -> T:
    """A scenegrep Parquet file of one kind (``what``: trace or map) converted from its table."""
    with reading(path, f"scenegrep Parquet {what}", pa.ArrowException):
        table = pq.read_table(path)
        if not is_kind(table.schema):
            raise UserError(f"a Parquet file without scenegrep {what} metadata", at(path))
        return convert(table)


def read_trace(path: str | Path) -> LabelTrace:
    """Read a scenegrep Parquet trace. A relative map path is relative to the trace's folder
    (as :func:`~scenegrep.writers.write_trace_parquet` stores it), never to the working directory."""
    trace = _read(path, "trace", is_trace_table, trace_from_table)
    source = trace.map_source
    if source is None or Path(source.path).is_absolute():
        return trace
    return replace(trace, map_source=replace(source, path=os.path.normpath(Path(path).parent / source.path)))


def read_map(path: str | Path) -> RoadMap:
    """Read a scenegrep Parquet road map."""
    return _read(path, "map", is_map_table, map_from_table)
