"""A dataset's traces read back: the Parquet file and road map the catalog names for a trace id."""

from __future__ import annotations

from pathlib import Path

from .. import readers
from ..errors import UserError, at
from ..model import LabelTrace, RoadMap
from .catalog import Catalog, catalog_file


def load_trace(root: Path, trace_id: str) -> tuple[LabelTrace, RoadMap | None]:
    """The trace ``trace_id`` of the dataset at ``root`` and its road map (None without one), as
    ingest stored them; UserError for an unknown trace or one whose files the catalog names outside
    the dataset."""
    with Catalog(root, read_only=True) as catalog:
        found = catalog.rows(
            "SELECT t.file, m.file FROM traces t LEFT JOIN maps m ON t.map_id = m.map_id WHERE t.trace_id = ?",
            [trace_id],
        )
    if not found:
        raise UserError(f"the dataset has no trace {trace_id!r}", at(root))
    trace_file, map_file = found[0]
    trace = readers.read_trace(catalog_file(root, trace_file), "scenegrep-parquet")
    road_map = None if map_file is None else readers.read_map(catalog_file(root, map_file))
    return trace, road_map
