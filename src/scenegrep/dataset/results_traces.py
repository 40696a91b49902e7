"""A results table with the traces it was computed on: the data every reader of results starts from.

A results table names traces by ``trace_id``; their Parquet files and road maps are found in
the dataset's catalog. The dataset is the one given, or the one the results file lies in
(``DATASET/runs/<run_id>/results.parquet``). The query behind the results (for the query text,
its options and a SpRE's classes) is the catalog's run of the table's ``run_id``. Results of a
query over files (not inside a dataset) name the file each trace came from (``source``): the
trace is read from it as the query read it, and the query is the one the results file records.

The exporters (``scenegrep export``) read traces through :class:`ResultsTraces`; the views add
drawing on top of it (:class:`scenegrep.view.sources.ResultsSource`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Self

import pyarrow.compute as pc

from ..errors import UserError
from ..model import LabelTrace
from ..wording import numbered
from .catalog import CATALOG_FILE, Catalog
from .results import Results
from .traces import load_trace


@dataclass(frozen=True)
class QueryInfo:
    """The query behind a results table: its kind ('scenario', 'scene', 'spre'), text and options."""

    kind: str
    text: str
    options: Mapping[str, Any] = field(default_factory=dict)


def find_dataset(path: str | Path) -> Path | None:
    """The dataset directory holding ``path`` (a results file), or None."""
    for folder in Path(path).resolve().parents:
        if (folder / CATALOG_FILE).is_file():
            return folder
    return None


@dataclass(frozen=True)
class ResultsTraces:
    """A results table with the dataset that holds its traces (``root``; None: each trace is read
    from its source file) and its query."""

    results: Results
    root: Path | None
    query: QueryInfo | None

    @classmethod
    def open(cls, path: str | Path, dataset: str | Path | None = None) -> Self:
        """The results at ``path`` (a run directory, Parquet, JSON lines or CSV) and their dataset: the
        one given, else the one the file lies in, else none (a query over files). UserError for a
        file that is no results table."""
        results = Results.read(path)
        return cls.of_results(results, Path(dataset).resolve() if dataset is not None else find_dataset(path))

    @classmethod
    def of_results(cls, results: Results, dataset: Path | None) -> Self:
        """Results just computed: a run over the dataset at ``dataset``, or (None) a query over files."""
        return cls(results, None, recorded_query(results.query)) if dataset is None else cls.of_run(dataset, results)

    @classmethod
    def of_run(cls, root: Path, results: Results) -> Self:
        """A run's results over the dataset at ``root``."""
        return cls(results, root, query_of(root, results.run_id) or recorded_query(results.query))

    def trace_ids(self) -> list[str]:
        """The traces of the table, in its order, each once."""
        return list(dict.fromkeys(self.results.table["trace_id"].to_pylist()))

    def rows_of(self, trace_id: str) -> list[dict[str, Any]]:
        """The table's rows of one trace, in table order."""
        table = self.results.table
        return table.filter(pc.equal(table["trace_id"], trace_id)).to_pylist()

    def load(self, trace_id: str) -> tuple[Any, Any]:
        """One trace of the table and its road map, from the dataset or from its source file; a
        scenario query's trace with the labels the query read (:mod:`scenegrep.dataset.labelling`).
        UserError for a trace the table or the dataset does not have."""
        if self.root is not None:
            return self._as_queried(trace_id, *load_trace(self.root, trace_id))
        from .files import read_queried_trace

        rows = self.rows_of(trace_id)
        if not rows:
            raise UserError(f"the results have no trace {trace_id!r}")
        choice = self.query.options.get("unknown_layers") if self.query is not None else None
        return read_queried_trace(rows[0]["source"], trace_id, unknown_layers=choice)

    def trace(self, trace_id: str) -> LabelTrace:
        """One trace of the table as the query read it (:meth:`load` without the road map)."""
        return self.load(trace_id)[0]

    def _as_queried(self, trace_id: str, trace: Any, road_map: Any) -> tuple[Any, Any]:
        """A dataset's trace and road map, labelled as the results' scenario query read it."""
        if self.query is None or self.query.kind != "scenario" or self.root is None:
            return trace, road_map
        from .labelling import as_queried

        mode = self.query.options.get("unknown_layers")
        return as_queried(self.root, trace_id, trace, road_map, mode), road_map

    def object_kinds(self, trace_ids: set[str]) -> dict[tuple[str, str], str]:
        """(trace_id, object_id) -> canonical kind, for the given traces."""
        if self.root is not None:
            with Catalog(self.root, read_only=True) as catalog:
                found = catalog.rows(
                    "SELECT trace_id, object_id, kind FROM objects WHERE list_contains(?, trace_id)",
                    [sorted(trace_ids)],
                )
            return {(t, o): k for t, o, k in found}
        from .statistics import TraceStatistics

        kinds = {}
        for trace_id in trace_ids:
            objects = TraceStatistics.of(self.trace(trace_id)).objects
            kinds.update(
                {(trace_id, o): k for o, k in zip(objects["object_id"].to_pylist(), objects["kind"].to_pylist())}
            )
        return kinds

    def matched_trace_ids(self) -> list[str]:
        """The traces with a match, in table order."""
        return list(dict.fromkeys(self.results.matches["trace_id"].to_pylist()))

    def match_row(self, number: int) -> dict[str, Any]:
        """The ``number``-th match of the table (0-based, in table order); UserError if there is none."""
        matches = self.results.matches
        if not 0 <= number < matches.num_rows:
            raise UserError(f"--match {number}: the results have {numbered(matches.num_rows, 'match')}")
        return matches.slice(number, 1).to_pylist()[0]


def query_of(root: Path, run_id: str) -> QueryInfo | None:
    """The query of a run of the dataset (None when the run is unknown)."""
    if not run_id:
        return None
    with Catalog(root, read_only=True) as catalog:
        found = catalog.rows("SELECT kind, query, options FROM runs WHERE run_id = ?", [run_id])
    if not found:
        return None
    kind, text, options = found[0]
    return QueryInfo(kind, text, json.loads(options or "{}"))


def recorded_query(key: str) -> QueryInfo | None:
    """The query a results file records (:meth:`QuerySpec.key`), or None."""
    if not key:
        return None
    kind, text, options = json.loads(key)
    return QueryInfo(kind, text, options)
