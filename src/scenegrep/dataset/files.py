"""A query over files: the dataset engine's per-trace path for traces that are not ingested.

The sources under the given paths are found as ``ingest`` finds them
(:func:`.ingest.discover`); each trace is read as ingest reads it (:func:`.ingest.prepare_trace`:
its own road map, unless the query reads no map (a SpRE); labelled with that map when it has no
behaviour labels, for a scenario query, the only kind that reads labels), planned with the planner's SQL
on a catalog in memory (:class:`.plan.TracePlanner`), and queried by the engine's per-trace
function (:func:`.queries.query_trace`). So its rows, trace ids included, equal those of the
same query over a dataset that ingested the same paths. A path, source or trace that fails gives
a 'failed' row and the others go on.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pyarrow as pa

from .. import readers
from ..errors import UserError, at, failure_text
from ..model import LabelTrace, RoadMap
from ..model.layers import UnknownLayers
from .ingest import Source, catalog_row, discover, prepare_trace, trace_id_of
from .plan import TracePlanner, needs_of
from .queries import (
    ORDER,
    QuerySpec,
    compiled,
    decisions_while,
    match_trace,
    pruned_row,
    query_trace,
    results_table,
    spec_choice,
    uses_map,
)
from .results import Results
from .run import run_id_of
from .statistics import time_origin_ns
from .vocabulary import Vocabulary, channels_of, query_warnings

RowsCallback = Callable[[list[dict[str, Any]]], None]


def query_files(
    paths: list[str], spec: QuerySpec, map_path: str | None = None, on_rows: RowsCallback | None = None
) -> Results:
    """Run ``spec`` over every trace under ``paths``; ``map_path`` is the road map of traces
    without their own (:func:`scenegrep.readers.with_given_map`: a trace naming its own map fails with it). ``on_rows``
    sees each trace's rows (a failed path's or source's row), with every column, as soon as they
    are ready. The results are ordered as a dataset run's, with its run id, and count the
    decisions the choice for unknown map layers affected, as a run's do."""
    sources, bad = discover(paths)
    vocabulary = Vocabulary()
    tables, assumed = decisions_while(spec, lambda: _tables(spec, sources, bad, map_path, on_rows, vocabulary))
    table = pa.concat_tables([results_table([]), *tables]).sort_by(ORDER)
    warnings = query_warnings(spec, compiled(spec), vocabulary)
    return Results(table, run_id_of(spec), query=spec.key(), assumed=assumed, warnings=warnings)


def _tables(
    spec: QuerySpec,
    sources: list[Source],
    bad: list[tuple[str, str]],
    map_path: str | None,
    on_rows: RowsCallback | None,
    vocabulary: Vocabulary,
) -> list[pa.Table]:
    """Each batch of rows (:func:`_batches`) as a table, shown to ``on_rows`` as it is ready; the
    names of the traces read go into ``vocabulary``."""
    tables = []
    with TracePlanner(needs_of(spec, compiled(spec))) as planner:
        for batch in _batches(spec, planner, sources, bad, map_path, vocabulary):
            tables.append(results_table(batch))
            if on_rows is not None:
                on_rows(tables[-1].to_pylist())
    return tables


def read_queried_trace(
    source: str, trace_id: str, map_path: str | None = None, unknown_layers: str | None = None
) -> tuple[LabelTrace, RoadMap | None]:
    """The trace ``trace_id`` of a query over files and its road map (its own, else ``map_path``'s:
    :func:`scenegrep.readers.with_given_map`),
    read from its ``source`` as the query read it, labelled under the query's choice for unknown
    map layers (UserError if the source no longer holds it)."""
    for number, trace in enumerate(readers.read_traces(source)):
        if trace_id_of(source, trace.name, number) == trace_id:
            return prepare_trace(trace, True, UnknownLayers(unknown_layers), map_path)
    raise UserError(f"holds no trace {trace_id!r} (changed since the query?)", at(source))


def _batches(
    spec: QuerySpec,
    planner: TracePlanner,
    sources: list[Source],
    bad: list[tuple[str, str]],
    map_path: str | None,
    vocabulary: Vocabulary,
) -> Iterator[list[dict[str, Any]]]:
    """The rows of each bad path, then of each trace of each source, in order."""
    for path, error in bad:
        yield [_failed(path, 0, error)]
    for source in sources:
        yield from _source_rows(spec, planner, source, map_path, vocabulary)


def _failed(path: str, number: int, error: str) -> dict[str, Any]:
    """The row of a path or source that gave no trace (or stopped giving them) at ``number``."""
    name = Path(path).name
    identity = {"trace_id": trace_id_of(path, name, number), "name": name, "source": path, "time_origin_ns": 0}
    return {**identity, "status": "failed", "match": -1, "error": error}


def _source_rows(
    spec: QuerySpec, planner: TracePlanner, source: Source, map_path: str | None, vocabulary: Vocabulary
) -> Iterator[list[dict[str, Any]]]:
    """Each trace's rows of one source, then, if reading it failed, the source's failed row."""
    number = 0
    try:
        for number, trace in enumerate(readers.read_traces(source.path, source.format)):
            yield _trace_rows(spec, planner, source.path, number, trace, map_path, vocabulary)
    except Exception as exc:  # a bad source must not stop the others
        yield [_failed(source.path, number, failure_text(exc, source.path))]


def _trace_rows(
    spec: QuerySpec,
    planner: TracePlanner,
    source: str,
    number: int,
    trace: LabelTrace,
    map_path: str | None,
    vocabulary: Vocabulary,
) -> list[dict[str, Any]]:
    trace_id = trace_id_of(source, trace.name, number)
    identity = {"trace_id": trace_id, "name": trace.name, "source": source, "time_origin_ns": time_origin_ns(trace)}

    def rows() -> list[dict[str, Any]]:
        labelled = spec.kind == "scenario"
        prepared, road_map = (
            prepare_trace(trace, labelled, spec_choice(spec), map_path) if uses_map(spec) else (trace, None)
        )
        row, statistics = catalog_row(prepared, trace_id, source, "", None)
        vocabulary.add_counts(statistics.frame_counts)
        vocabulary.add_channels(channels_of(prepared))
        reason = planner.prune_reason(row, statistics)
        if reason is not None:
            return [pruned_row(reason)]
        return match_trace(spec, prepared, road_map)

    return query_trace(identity, source, rows)
