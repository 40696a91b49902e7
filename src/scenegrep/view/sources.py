"""Where views get their data: a results table and the dataset it was computed on, or a trace file.

A results table's traces, road maps and query are found as the Python API finds them
(:class:`scenegrep.dataset.results_traces.ResultsTraces`: the dataset's catalog, or each trace's
source file for a query over files); :class:`ResultsSource` adds each trace's view.
"""

from __future__ import annotations

import json
from pathlib import Path

from .. import readers
from ..dataset.results_traces import ResultsTraces
from .data import TraceView, build_view


class ResultsSource(ResultsTraces):
    """A results table with its traces (:class:`~scenegrep.dataset.results_traces.ResultsTraces`)
    and the view of each."""

    def view(self, trace_id: str) -> TraceView:
        """The view of one trace of the table with its rows."""
        trace, road_map = self.load(trace_id)
        return build_view(trace, road_map, self.rows_of(trace_id), self.query, trace_id)


def trace_file_view(path: str | Path, map_path: str | Path | None = None) -> TraceView:
    """The view of a trace file of any readable format, on its own map or ``map_path``."""
    trace = readers.read_trace(path)
    source = map_path if map_path is not None else trace.map_source
    road_map = None if source is None else readers.read_map(source)
    return build_view(trace, road_map)


def is_results(path: str | Path) -> bool:
    """Whether ``path`` holds a results table (rather than a trace): a Parquet, JSON-lines or CSV
    file with the results' ``trace_id`` and ``status`` columns."""
    import pyarrow.parquet as pq

    path = Path(path)
    if not path.is_file():
        return False
    suffix = path.suffix.lower()
    try:
        if suffix == ".parquet":
            names = set(pq.read_schema(path).names)
        elif suffix in (".json", ".jsonl", ".csv"):
            with open(path, encoding="utf-8") as stream:
                first = stream.readline()
            names = set(json.loads(first)) if suffix != ".csv" else set(first.strip().split(","))
        else:
            return False
    except (OSError, ValueError, TypeError):
        return False
    return {"trace_id", "status"} <= names
