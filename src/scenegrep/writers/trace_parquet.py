"""scenegrep's Parquet trace and map files (layouts in :mod:`scenegrep.model.trace_arrow`
and :mod:`scenegrep.model.map_arrow`), written atomically."""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path

import pyarrow.parquet as pq

from ..model import LabelTrace, RoadMap
from ..model.map_arrow import map_to_table
from ..model.trace_arrow import trace_to_table
from .atomic import atomic_path

ROW_GROUP_ROWS = 1 << 17


def write_trace_parquet(trace: LabelTrace, path: str | Path) -> Path:
    """Write a trace as one zstd-compressed Parquet file; returns the path. A relative map path
    (relative to the working directory, as readers give it) is stored relative to the file's
    folder, where :func:`~scenegrep.readers.trace_parquet.read_trace` resolves it."""
    source = trace.map_source
    if source is not None and not os.path.isabs(source.path):
        trace = replace(trace, map_source=replace(source, path=os.path.relpath(source.path, Path(path).parent)))
    with atomic_path(path) as tmp:
        pq.write_table(trace_to_table(trace), tmp, compression="zstd", row_group_size=ROW_GROUP_ROWS)
    return Path(path)


def write_map_parquet(road_map: RoadMap, path: str | Path) -> Path:
    """Write a road map as one zstd-compressed Parquet file; returns the path."""
    with atomic_path(path) as tmp:
        pq.write_table(map_to_table(road_map), tmp, compression="zstd")
    return Path(path)
