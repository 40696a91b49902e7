"""The dataset engine: ingest inputs into a dataset (Parquet traces + a DuckDB catalog) and run
any query kind over all its traces, pruned by the catalog, in parallel.

    import scenegrep
    ds = scenegrep.open_dataset("fleet", create=True)
    ds.ingest(["recordings/"])
    results = ds.scenario("examples/queries/s1_lane_change_stationary_car.scenic", window=75)
    results.to_pandas()
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pyarrow as pa

from .catalog import Catalog
from .ingest import IngestReport, ingest
from .plan import Plan
from .queries import QuerySpec
from .results import Results
from .run import RunOptions, run_query


class Dataset:
    """A dataset directory (see :mod:`scenegrep.dataset.ingest` for its layout)."""

    def __init__(self, path: str | Path):
        self.path = Path(path).resolve()

    def sql(self, query: str, parameters: list[Any] | None = None) -> pa.Table:
        """Run SQL over the catalog (read-only); e.g. ``SELECT * FROM results WHERE status = 'match'``."""
        with Catalog(self.path, read_only=True) as catalog:
            return catalog.sql(query, parameters)

    def traces(self) -> pa.Table:
        """The catalog's ``traces`` table."""
        return self.sql("SELECT * FROM traces ORDER BY trace_id")

    def ingest(
        self, sources: list[str], jobs: int | None = None, label: bool = True, unknown_layers: str | None = None
    ) -> IngestReport:
        """Add (or update) the traces of ``sources``, labelled under the choice ``unknown_layers``
        for map layers a map does not publish; see :func:`scenegrep.dataset.ingest.ingest`."""
        return ingest([str(s) for s in sources], self.path, jobs, label, unknown_layers=unknown_layers)

    def query(self, kind: str, query: str | Path, *, run: RunOptions | None = None, **options: Any) -> Results:
        """Run a query of ``kind`` ('scenario', 'scene' or 'spre') over every trace. ``query`` is a
        SpRE, or a Scenic program's text or ``.scenic`` path; ``options`` are the kind's options
        (:data:`scenegrep.dataset.queries.OPTIONS`), ``run`` how to run it."""
        if kind != "spre" and Path(query).suffix == ".scenic" and Path(query).is_file():
            spec = QuerySpec.from_file(kind, query, **options)
        else:
            spec = QuerySpec.of(kind, str(query), **options)
        return run_query(self.path, spec, run or RunOptions())

    def scenario(self, program: str | Path, window: int | str, **options: Any) -> Results:
        """A Scenic scenario query with a window of ``window`` frames ('5s': seconds; 'all')."""
        return self.query("scenario", program, window=window, **options)

    def scene(self, program: str | Path, **options: Any) -> Results:
        """A Scenic scene query."""
        return self.query("scene", program, **options)

    def spre(self, pattern: str, **options: Any) -> Results:
        """A Spatial Regular Expression query (offline: non-overlapping leftmost-longest matches)."""
        return self.query("spre", pattern, **options)


def open_dataset(path: str | Path, create: bool = False) -> Dataset:
    """The dataset at ``path`` (UserError if there is none, unless ``create``)."""
    Catalog(Path(path).resolve(), create=create).close()
    return Dataset(path)


__all__ = ["Dataset", "IngestReport", "Plan", "QuerySpec", "Results", "RunOptions", "ingest", "open_dataset"]
