"""scenegrep's Parquet trace and map files (layouts in :mod:`scenegrep.model.trace_arrow`
and :mod:`scenegrep.model.map_arrow`), written atomically."""

from __future__ import annotations

from pathlib import Path

import pyarrow.parquet as pq

from ..model import LabelTrace, RoadMap
from ..model.map_arrow import map_to_table
from ..model.trace_arrow import trace_to_table
from .atomic import atomic_path

ROW_GROUP_ROWS = 1 << 17


def write_trace_parquet(trace: LabelTrace, path: str | Path) -> Path:
    """Write a trace as one zstd-compressed Parquet file; returns the path."""
    with atomic_path(path) as tmp:
        pq.write_table(trace_to_table(trace), tmp, compression="zstd", row_group_size=ROW_GROUP_ROWS)
    return Path(path)


def write_map_parquet(road_map: RoadMap, path: str | Path) -> Path:
    """Write a road map as one zstd-compressed Parquet file; returns the path."""
    with atomic_path(path) as tmp:
        pq.write_table(map_to_table(road_map), tmp, compression="zstd")
    return Path(path)
