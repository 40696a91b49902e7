"""A query run's results table (columns in :mod:`scenegrep.dataset.queries`) and its views."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TextIO

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from ..errors import UserError, at
from .queries import RESULTS_SCHEMA


@dataclass(frozen=True)
class Results:
    """The results of a run: the table, the run's id and its ``status`` ('finished' or
    'interrupted': then only the traces done so far have rows besides the pruned ones)."""

    table: pa.Table
    run_id: str = ""
    status: str = "finished"

    @classmethod
    def read(cls, path: str | Path) -> Results:
        """Results from a Parquet file written by a run (UserError if it is not one)."""
        try:
            table = pq.read_table(path)
        except (OSError, pa.ArrowInvalid) as exc:
            raise UserError(f"cannot read results: {str(exc).splitlines()[0]}", at(path)) from None
        missing = set(RESULTS_SCHEMA.names) - set(table.column_names)
        if missing:
            raise UserError(f"not a scenegrep results table (no column {sorted(missing)[0]!r})", at(path))
        return cls(table.select(RESULTS_SCHEMA.names).cast(RESULTS_SCHEMA))

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
        """One JSON object per row (correspondence decoded)."""
        for row in self.table.to_pylist():
            row["correspondence"] = json.loads(row["correspondence"]) if row["correspondence"] else None
            stream.write(json.dumps(row, allow_nan=True) + "\n")

    def write_csv(self, stream: TextIO) -> None:
        """The table as CSV with a header row."""
        writer = csv.writer(stream, lineterminator="\n")
        writer.writerow(self.table.column_names)
        for row in self.table.to_pylist():
            writer.writerow(["" if v is None else v for v in row.values()])

    def write_parquet(self, path: str | Path) -> None:
        """The table as a Parquet file, written atomically."""
        from ..writers.atomic import atomic_path

        with atomic_path(path) as tmp:
            pq.write_table(self.table, tmp, compression="zstd")
