"""The dataset catalog: an embedded DuckDB database beside the dataset's Parquet files.

Tables (``trace_id`` joins them; frames are positions 0..F-1 of a trace, times seconds):

- ``sources(path, format, checksum, traces, ingested_at)``: every ingested input and the
  SHA-256 of its bytes; ``source_errors(path, error, failed_at)``: inputs that failed to ingest.
- ``traces(trace_id, name, source_path, file, map_id, frames, duration_s, period_s, objects,
  observations, ego, has_behaviours, has_images, time_origin_ns, labelled_under)``; ``file`` is
  relative to the dataset directory; ``labelled_under`` is the choice for unknown map layers ingest
  labelled the trace under (:mod:`scenegrep.dataset.labelling`: NULL when ingest did not label it;
  'unknown' in rows of a catalog written before the column, which opening it for writing adds).
  ``maps(map_id, file, source_path, format, key)``.
- ``objects(trace_id, object_id, category, kind, first_frame, last_frame, observations)``.
- ``frame_counts(trace_id, frame, category, kind, layer, count)``: objects (``layer`` 'objects')
  or image boxes ('images') of each class in each frame where there is any.
- ``labels(trace_id, label, observations, objects)``: behaviour label statistics (of the labels
  the trace file holds; the planner does not read them, see :mod:`scenegrep.dataset.plan`).
- ``runs(run_id, kind, query, options, status, started_at, finished_at, traces, pruned, matched,
  failed)`` and ``results(run_id, trace_id, ...)``: query runs and their results table (the columns
  of :data:`scenegrep.dataset.queries.RESULTS_SCHEMA`).

A trace is visible when its ``traces`` row is committed; its rows of every table are written
in one transaction, after its Parquet file is complete.
"""

from __future__ import annotations

import time
from datetime import datetime
from pathlib import Path
from typing import Any

import duckdb
import pyarrow as pa

from ..errors import UserError, at

SCHEMA_VERSION = "1"
CATALOG_FILE = "catalog.duckdb"

SCHEMA = """
CREATE TABLE IF NOT EXISTS meta (key VARCHAR PRIMARY KEY, value VARCHAR);
CREATE TABLE IF NOT EXISTS sources (
    path VARCHAR PRIMARY KEY, format VARCHAR, checksum VARCHAR, traces INTEGER, ingested_at TIMESTAMP);
CREATE TABLE IF NOT EXISTS source_errors (path VARCHAR PRIMARY KEY, error VARCHAR, failed_at TIMESTAMP);
CREATE TABLE IF NOT EXISTS maps (map_id VARCHAR PRIMARY KEY, file VARCHAR, source_path VARCHAR, format VARCHAR,
    key VARCHAR);
CREATE TABLE IF NOT EXISTS traces (
    trace_id VARCHAR PRIMARY KEY, name VARCHAR, source_path VARCHAR, file VARCHAR, map_id VARCHAR,
    frames BIGINT, duration_s DOUBLE, period_s DOUBLE, objects BIGINT, observations BIGINT, ego VARCHAR,
    has_behaviours BOOLEAN, has_images BOOLEAN, time_origin_ns BIGINT);
CREATE TABLE IF NOT EXISTS objects (
    trace_id VARCHAR, object_id VARCHAR, category VARCHAR, kind VARCHAR, first_frame BIGINT, last_frame BIGINT,
    observations BIGINT);
CREATE TABLE IF NOT EXISTS frame_counts (
    trace_id VARCHAR, frame BIGINT, category VARCHAR, kind VARCHAR, layer VARCHAR, count BIGINT);
CREATE TABLE IF NOT EXISTS labels (trace_id VARCHAR, label VARCHAR, observations BIGINT, objects BIGINT);
CREATE TABLE IF NOT EXISTS runs (
    run_id VARCHAR PRIMARY KEY, kind VARCHAR, query VARCHAR, options VARCHAR, status VARCHAR,
    started_at TIMESTAMP, finished_at TIMESTAMP, traces BIGINT, pruned BIGINT, matched BIGINT, failed BIGINT);
CREATE TABLE IF NOT EXISTS results (
    run_id VARCHAR, trace_id VARCHAR, name VARCHAR, source VARCHAR, status VARCHAR, match INTEGER,
    correspondence VARCHAR, start_frame BIGINT, end_frame BIGINT, start_time DOUBLE, end_time DOUBLE,
    time_origin_ns BIGINT, explanation VARCHAR, error VARCHAR);
ALTER TABLE results ADD COLUMN IF NOT EXISTS values VARCHAR;
ALTER TABLE results ADD COLUMN IF NOT EXISTS objects VARCHAR;
ALTER TABLE results ADD COLUMN IF NOT EXISTS intervals VARCHAR;
ALTER TABLE traces ADD COLUMN IF NOT EXISTS labelled_under VARCHAR DEFAULT 'unknown';
"""

PER_TRACE_TABLES = ("objects", "frame_counts", "labels")
LOCK_WAIT = 10.0
"""Seconds to wait for another process's writing connection to close (runs and ingest hold one
only briefly: for their plan and their commits) before the catalog is a user error."""


def _connect(path: Path | None, read_only: bool) -> duckdb.DuckDBPyConnection:
    """A DuckDB connection to ``path`` (None: in memory), waiting up to :data:`LOCK_WAIT` seconds
    while another process holds the file's lock."""
    deadline = time.monotonic() + LOCK_WAIT
    while True:
        try:
            return duckdb.connect(":memory:" if path is None else str(path), read_only=read_only)
        except duckdb.IOException as exc:
            if "Could not set lock" not in str(exc) or time.monotonic() > deadline:
                raise UserError(f"cannot open the catalog: {str(exc).splitlines()[0]}", at(path)) from None
            time.sleep(0.05)


def within(root: Path, name: str) -> Path | None:
    """``root / name`` with symbolic links resolved, or None where that lies outside ``root``."""
    base = root.resolve()
    path = (base / name).resolve()
    return path if path.is_relative_to(base) else None


def catalog_file(root: Path, name: str) -> Path:
    """The file a catalog row names (a trace's or a map's Parquet file, relative to the dataset
    folder ``root``): UserError if it lies outside the folder (a stranger's catalog may name any
    path)."""
    path = within(root, name)
    if path is None:
        raise UserError(f"the catalog names a file outside the dataset: {name!r}", at(root))
    return path


def _with_trace_id(table: pa.Table, trace_id: str) -> pa.Table:
    return table.add_column(0, "trace_id", pa.array([trace_id] * table.num_rows, pa.string()))


class Catalog:
    """A connection to a dataset's catalog; use as a context manager (commits on close).

    ``read_only`` connections may be open in several processes at once; a writing connection
    excludes every other process (DuckDB's file lock), so long runs close it while they work.
    A ``root`` of None is an empty catalog in memory whose tables :meth:`show_trace` provides
    (a query over files plans each trace with one)."""

    def __init__(self, root: Path | None, create: bool = False, read_only: bool = False):
        self.root = root
        path = None if root is None else root / CATALOG_FILE
        if path is not None and not create and not path.is_file():
            raise UserError("not a scenegrep dataset (no catalog.duckdb; create one with scenegrep ingest)", at(root))
        if path is not None and create:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as error:
                raise UserError(f"cannot make the dataset directory: {error.strerror}", at(root)) from None
        self.db = _connect(path, read_only)
        if path is not None and not read_only:
            self.db.execute(SCHEMA)
            self.db.execute("INSERT OR REPLACE INTO meta VALUES ('schema_version', ?)", [SCHEMA_VERSION])

    def __enter__(self) -> Catalog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self.db.close()

    def sql(self, query: str, parameters: list[Any] | None = None) -> pa.Table:
        """Run a SQL statement; its result as an Arrow table."""
        return self.db.sql(query, params=parameters or None).to_arrow_table()

    def rows(self, query: str, parameters: list[Any] | None = None) -> list[tuple]:
        """Run a SQL statement; its result as tuples."""
        return self.db.execute(query, parameters or []).fetchall()

    def show_trace(self, row: dict[str, Any], statistics: Any) -> None:
        """(A catalog in memory) let ``traces`` and the per-trace tables hold one trace only: its
        ``traces`` row and its :class:`~scenegrep.dataset.statistics.TraceStatistics`."""
        self.db.register("traces", pa.Table.from_pylist([row]))
        for table in PER_TRACE_TABLES:
            self.db.register(table, _with_trace_id(getattr(statistics, table), row["trace_id"]))

    # ------------------------------------------------------------------ ingest
    def checksums(self) -> dict[str, str]:
        """Ingested source path -> checksum."""
        return dict(self.rows("SELECT path, checksum FROM sources"))

    def trace_files(self, source_path: str) -> list[str]:
        """The files (relative to the dataset) of the traces from one source."""
        return [f for (f,) in self.rows("SELECT file FROM traces WHERE source_path = ?", [source_path])]

    def replace_sources(self, batch: list[tuple[dict[str, Any], list[tuple[dict[str, Any], Any]]]]) -> None:
        """In one transaction, for each (source row, traces) of ``batch``: forget the source's
        previous traces, add ``traces`` (pairs of a ``traces`` row and its
        :class:`~scenegrep.dataset.statistics.TraceStatistics`) and the source's row."""
        if not batch:
            return
        db = self.db
        paths = [source["path"] for source, _ in batch]
        traces = [pair for _, pairs in batch for pair in pairs]
        db.begin()
        try:
            self._forget_sources(paths)
            if traces:
                self._insert("traces", pa.Table.from_pylist([row for row, _ in traces]))
            for table in PER_TRACE_TABLES:
                parts = [_with_trace_id(getattr(stats, table), row["trace_id"]) for row, stats in traces]
                if parts:
                    self._insert(table, pa.concat_tables(parts))
            now = datetime.now()
            sources = [{**source, "traces": len(pairs), "ingested_at": now} for source, pairs in batch]
            self._insert("sources", pa.Table.from_pylist(sources))
            db.execute("DELETE FROM source_errors WHERE path IN (SELECT unnest(?))", [paths])
            db.commit()
        except BaseException:
            db.rollback()
            raise

    def _forget_sources(self, paths: list[str]) -> None:
        old = "SELECT trace_id FROM traces WHERE source_path IN (SELECT unnest(?))"
        for table in PER_TRACE_TABLES:
            self.db.execute(f"DELETE FROM {table} WHERE trace_id IN ({old})", [paths])
        self.db.execute("DELETE FROM traces WHERE source_path IN (SELECT unnest(?))", [paths])
        self.db.execute("DELETE FROM sources WHERE path IN (SELECT unnest(?))", [paths])

    def _insert(self, table: str, rows: pa.Table) -> None:
        """Insert an Arrow table's columns into the table's columns of the same names."""
        names = ", ".join(rows.column_names)
        self.db.register("incoming", rows)
        self.db.execute(f"INSERT INTO {table} ({names}) SELECT {names} FROM incoming")
        self.db.unregister("incoming")

    def add_map(self, row: dict[str, Any]) -> None:
        """Record a converted road map (idempotent)."""
        self.db.execute("INSERT OR REPLACE INTO maps VALUES (?, ?, ?, ?, ?)", list(row.values()))

    def record_source_error(self, path: str, error: str) -> None:
        self.db.execute("INSERT OR REPLACE INTO source_errors VALUES (?, ?, now())", [path, error])

    # ------------------------------------------------------------------ runs
    def start_run(self, run_id: str, kind: str, query: str, options: str) -> None:
        """Record a run as running (keeping an interrupted run's start when resumed)."""
        self.db.execute(
            "INSERT INTO runs (run_id, kind, query, options, status, started_at) VALUES (?, ?, ?, ?, 'running', now()) "
            "ON CONFLICT (run_id) DO UPDATE SET status = 'running', finished_at = NULL",
            [run_id, kind, query, options],
        )

    def finish_run(self, run_id: str, status: str, results: pa.Table, counts: dict[str, int]) -> None:
        """Replace the run's results and record its status and counts, in one transaction."""
        db = self.db
        db.begin()
        try:
            db.execute("DELETE FROM results WHERE run_id = ?", [run_id])
            db.register("incoming", results)
            db.execute("INSERT INTO results BY NAME SELECT ? AS run_id, * FROM incoming", [run_id])
            db.unregister("incoming")
            db.execute(
                "UPDATE runs SET status = ?, finished_at = now(), traces = ?, pruned = ?, matched = ?, failed = ? "
                "WHERE run_id = ?",
                [status, counts["traces"], counts["pruned"], counts["matched"], counts["failed"], run_id],
            )
            db.commit()
        except BaseException:
            db.rollback()
            raise
