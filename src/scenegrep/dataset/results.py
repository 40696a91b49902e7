"""A query run's results table (columns in :mod:`scenegrep.dataset.queries`) and its views."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable
from typing import Any, TextIO

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from ..errors import UserError, at
from .queries import RESULTS_SCHEMA

RESULTS_FILE = "results.parquet"
"""The results file of a run directory (``DATASET/runs/<run_id>/results.parquet``)."""

RUN_ID_KEY = b"scenegrep.run_id"
STATUS_KEY = b"scenegrep.status"
QUERY_KEY = b"scenegrep.query"
"""Keys of the run's id, status and query in a results Parquet file's metadata."""


@dataclass(frozen=True)
class Results:
    """The results of a run: the table, the run's id, its ``status`` ('finished' or
    'interrupted': then only the traces done so far have rows besides the pruned ones), its
    ``query`` (:meth:`QuerySpec.key <scenegrep.dataset.queries.QuerySpec.key>`; "" when unknown)
    and, per map layer, how many decisions of the run the choice for unknown layers affected
    (``assumed``), and the ``warnings`` for names the query uses that no searched trace has
    (:mod:`.vocabulary`): both for the report on stderr, not kept in results files."""

    table: pa.Table
    run_id: str = ""
    status: str = "finished"
    query: str = ""
    assumed: dict[str, int] = field(default_factory=dict)
    warnings: tuple[str, ...] = ()

    @classmethod
    def read(cls, path: str | Path) -> Results:
        """Results from a run directory or a file a run wrote: Parquet, JSON lines (``.json``,
        ``.jsonl``) or CSV (UserError if it is not a results table). The run id is the one the
        Parquet file records, else the name of the run directory its ``results.parquet`` lies in."""
        path = Path(path)
        if path.is_dir():
            path = path / RESULTS_FILE
        suffix = path.suffix.lower()
        try:
            if suffix in (".json", ".jsonl"):
                table = _from_rows(_json_rows(path))
            elif suffix == ".csv":
                table = _from_rows(_csv_rows(path))
            else:
                table = pq.read_table(path)
        except (OSError, ValueError, pa.ArrowException) as exc:
            raise UserError(f"cannot read results: {str(exc).splitlines()[0]}", at(path)) from None
        for name in set(LATER_COLUMNS) - set(table.column_names):
            table = table.append_column(name, pa.nulls(table.num_rows, pa.string()))
        missing = set(RESULTS_SCHEMA.names) - set(table.column_names)
        if missing:
            raise UserError(f"not a scenegrep results table (no column {sorted(missing)[0]!r})", at(path))
        metadata = table.schema.metadata or {}
        run_id = metadata.get(RUN_ID_KEY, b"").decode() or (path.parent.name if path.name == RESULTS_FILE else "")
        status = metadata.get(STATUS_KEY, b"finished").decode()
        query = metadata.get(QUERY_KEY, b"").decode()
        return cls(table.select(RESULTS_SCHEMA.names).cast(RESULTS_SCHEMA), run_id, status, query)

    def __len__(self) -> int:
        return self.table.num_rows

    def to_arrow(self) -> pa.Table:
        return self.table

    def to_pandas(self) -> Any:
        return self.table.to_pandas()

    def to_polars(self) -> Any:
        import polars

        return polars.from_arrow(self.table)

    def with_status(self, *statuses: str) -> pa.Table:
        """The rows of the given statuses."""
        return self.table.filter(pc.is_in(self.table["status"], pa.array(statuses)))

    @property
    def matches(self) -> pa.Table:
        return self.with_status("match")

    @property
    def failed(self) -> pa.Table:
        return self.with_status("failed")

    def traces_with(self, status: str) -> int:
        """How many distinct traces have a row of this status."""
        return len(set(self.with_status(status)["trace_id"].to_pylist()))

    def counts(self) -> dict[str, int]:
        """Traces in all, and matched, pruned and failed traces."""
        return {
            "traces": len(set(self.table["trace_id"].to_pylist())),
            "matched": self.traces_with("match"),
            "pruned": self.traces_with("pruned"),
            "failed": self.traces_with("failed"),
        }

    def write_json(self, stream: TextIO) -> None:
        """One JSON object per row (:func:`json_line`)."""
        for row in self.table.to_pylist():
            stream.write(json_line(row) + "\n")

    def write_csv(self, stream: TextIO) -> None:
        """The table as CSV with a header row (:func:`csv_writer`)."""
        write = csv_writer(stream)
        for row in self.table.to_pylist():
            write(row)

    def write_parquet(self, path: str | Path) -> None:
        """The table as a Parquet file, written atomically."""
        from ..writers.atomic import atomic_path

        with atomic_path(path) as tmp:
            metadata = {
                RUN_ID_KEY: self.run_id.encode(),
                STATUS_KEY: self.status.encode(),
                QUERY_KEY: self.query.encode(),
            }
            pq.write_table(self.table.replace_schema_metadata(metadata), tmp, compression="zstd")


LATER_COLUMNS = ("values", "objects", "intervals")
"""Columns added after results files were first written: null when a file lacks them."""

JSON_COLUMNS = ("correspondence", "values", "objects", "intervals")
"""Columns holding JSON text, written as JSON values in JSON lines."""


def json_line(row: dict[str, Any]) -> str:
    """A results row as one JSON Lines record (:mod:`scenegrep.json_lines`: numbers rounded), its
    JSON columns decoded (``Results.read`` reads it back)."""
    from ..json_lines import line

    decoded = {k: (json.loads(v) if v else None) if k in JSON_COLUMNS else v for k, v in row.items()}
    return line(decoded)


def csv_writer(stream: TextIO) -> Callable[[dict[str, Any]], None]:
    """Writes the header row of the results' columns, and returns a function that writes a row
    (numbers rounded as in JSON Lines)."""
    writer = csv.writer(stream, lineterminator="\n")
    writer.writerow(RESULTS_SCHEMA.names)

    def write(row: dict[str, Any]) -> None:
        writer.writerow(["" if row.get(name) is None else _cell(name, row[name]) for name in RESULTS_SCHEMA.names])

    return write


def _cell(name: str, value: Any) -> Any:
    """A CSV cell: numbers, and those in JSON columns, rounded as in JSON Lines (:mod:`scenegrep.json_lines`)."""
    from ..json_lines import line, rounded

    if name in JSON_COLUMNS and value:
        return line(json.loads(value))
    return rounded(value, name)


def _json_rows(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a JSON-lines results file (as ``write_json`` writes them)."""
    with open(path, encoding="utf-8") as stream:
        rows = [json.loads(line) for line in stream if line.strip()]
    for row in rows:
        for name in JSON_COLUMNS:
            if isinstance(row.get(name), dict):
                row[name] = json.dumps(row[name], sort_keys=name == "correspondence", allow_nan=True)
    return rows


def _csv_rows(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a CSV results file (empty cells are nulls)."""
    with open(path, encoding="utf-8", newline="") as stream:
        return [{k: (v if v != "" else None) for k, v in row.items()} for row in csv.DictReader(stream)]


def _text(value: Any) -> str | None:
    return None if value is None else str(value)


def _from_rows(rows: list[dict[str, Any]]) -> pa.Table:
    """Rows of text or JSON values as a table of the results' types."""
    if rows and not set(RESULTS_SCHEMA.names) - set(LATER_COLUMNS) <= set(rows[0]):
        missing = sorted(set(RESULTS_SCHEMA.names) - set(LATER_COLUMNS) - set(rows[0]))
        raise ValueError(f"not a scenegrep results table (no column {missing[0]!r})")
    columns = {
        field.name: pa.array([_text(row.get(field.name)) for row in rows], pa.string()).cast(field.type)
        for field in RESULTS_SCHEMA
    }
    return pa.table(columns, schema=RESULTS_SCHEMA)
