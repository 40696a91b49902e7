"""A query run over a dataset: plan, query the kept traces in parallel, keep the results.

A run's identity is a hash of its query and options (``run_id``). Its directory
``runs/<run_id>/`` holds ``query.json``, ``parts/`` (one Parquet file per finished chunk of
traces, each written atomically as the chunk completes) and, at the end, ``results.parquet``;
the same table goes into the catalog's ``results`` table (``WHERE run_id = ...``). Each part's
metadata keeps the decisions its chunk's worker made under the choice for unknown map layers
(:data:`ASSUMED_KEY`), so the results' count covers resumed parts too. A run
stopped by Ctrl-C keeps what is done (status 'interrupted'); one killed outright keeps its
parts. ``resume`` reuses the parts of a previous run of the same query and queries only the
traces without one, so the final results equal those of an uninterrupted run.
"""

from __future__ import annotations

import hashlib
import json
import math
import shutil
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from .catalog import Catalog, catalog_file
from .execute import default_jobs, run_all
from .labelling import catalog_value
from .plan import Plan, needs_of, plan
from .queries import ORDER, QuerySpec, TraceTask, compiled, pruned_row, results_table, run_tasks
from .results import RESULTS_FILE, Results
from .vocabulary import Vocabulary, query_warnings

MAX_CHUNK = 64
"""At most this many traces per task: results are saved (and progress shown) per chunk."""

ASSUMED_KEY = b"scenegrep.assumed"
"""Key of a part's decisions per unknown map layer (a JSON object) in its Parquet metadata."""

CHANNELS_KEY = b"scenegrep.channels"
"""Key of the image channels of a part's traces (a JSON list) in its Parquet metadata."""


@dataclass(frozen=True)
class RunOptions:
    """How to run: ``jobs`` workers (None: all cores), ``engine`` 'local' or 'ray' (with a
    cluster ``address``; None starts a local instance), ``resume`` a previous run, a fallback
    road map ``map_path`` for traces without one, and whether to show a ``progress`` bar (drawn
    only when standard error is a terminal, :mod:`scenegrep.progress`)."""

    jobs: int | None = None
    engine: str = "local"
    address: str | None = None
    resume: bool = False
    map_path: str | None = None
    progress: bool = False


def run_id_of(spec: QuerySpec) -> str:
    return hashlib.sha256(spec.key().encode()).hexdigest()[:12]


def run_query(
    root: Path, spec: QuerySpec, options: RunOptions, on_plan: Callable[[Plan], None] | None = None
) -> Results:
    """Run ``spec`` over the dataset at ``root``; see the module docstring. ``on_plan`` sees the
    plan before any trace is queried."""
    query = compiled(spec)
    run_id = run_id_of(spec)
    folder = root / "runs" / run_id
    vocabulary = Vocabulary()
    with Catalog(root) as catalog:
        planned = plan(catalog, needs_of(spec, query))
        maps = dict(catalog.rows("SELECT map_id, file FROM maps"))
        vocabulary.add_catalog(catalog)
        catalog.start_run(run_id, spec.kind, spec.text, json.dumps(dict(spec.options)))
    if on_plan is not None:
        on_plan(planned)
    parts = folder / "parts"
    if not options.resume and folder.exists():
        shutil.rmtree(folder)
    parts.mkdir(parents=True, exist_ok=True)
    (folder / "query.json").write_text(spec.key())
    done = _finished_traces(parts)
    todo = [_task(root, row, maps) for row in planned.kept if row["trace_id"] not in done]
    status = _execute(spec, todo, parts, options, len(planned.kept), len(done))
    return _finish(root, spec, status, parts, planned, vocabulary)


def identity_of(row: dict[str, Any]) -> dict[str, Any]:
    """The identity columns of a trace's result rows, from its ``traces`` row in the catalog."""
    return {
        "trace_id": row["trace_id"],
        "name": row["name"],
        "source": row["source_path"],
        "time_origin_ns": row["time_origin_ns"],
    }


def _task(root: Path, row: dict[str, Any], maps: dict[str, str]) -> TraceTask:
    """The task of a catalog ``traces`` row (UserError if the catalog names its files outside the dataset)."""
    map_file = maps.get(row["map_id"]) if row["map_id"] else None
    return TraceTask(
        row["trace_id"],
        row["name"],
        row["source_path"],
        str(catalog_file(root, row["file"])),
        None if map_file is None else str(catalog_file(root, map_file)),
        row["time_origin_ns"],
        catalog_value(row),
    )


def _finished_traces(parts: Path) -> set[str]:
    done: set[str] = set()
    for part in parts.glob("*.parquet"):
        done.update(pq.read_table(part, columns=["trace_id"])["trace_id"].to_pylist())
    return done


def _chunks(tasks: list[TraceTask], workers: int) -> list[list[TraceTask]]:
    size = max(1, min(MAX_CHUNK, math.ceil(len(tasks) / (workers * 16))))
    return [tasks[i : i + size] for i in range(0, len(tasks), size)]


def _execute(spec: QuerySpec, todo: list[TraceTask], parts: Path, options: RunOptions, total: int, done: int) -> str:
    """Query the traces, saving each chunk's rows as a part; 'finished' or 'interrupted'."""
    from ..progress import bar as progress_bar
    from ..writers.atomic import atomic_path

    chunks = _chunks(todo, options.jobs or default_jobs())
    work = [(spec, options.map_path, chunk) for chunk in chunks]
    bar = progress_bar(quiet=not options.progress, total=total, initial=done, unit="trace", leave=False)
    matched = 0
    try:
        for number, chunk in run_all(run_tasks, work, options.jobs, options.engine, options.address):
            name = hashlib.sha256("\0".join(t.trace_id for t in chunks[number]).encode()).hexdigest()[:16]
            metadata = {ASSUMED_KEY: json.dumps(chunk.assumed), CHANNELS_KEY: json.dumps(chunk.channels)}
            table = results_table(chunk.rows).replace_schema_metadata(metadata)
            with atomic_path(parts / f"{name}.parquet") as tmp:
                pq.write_table(table, tmp)
            matched += len({r["trace_id"] for r in chunk.rows if r["status"] == "match"})
            bar.set_postfix_str(f"{matched} matched", refresh=False)
            bar.update(len(chunks[number]))
    except KeyboardInterrupt:
        return "interrupted"
    finally:
        bar.close()
    return "finished"


def _assumed(parts: list[pa.Table]) -> dict[str, int]:
    """The decisions per unknown map layer that the parts' metadata records, summed."""
    total: Counter[str] = Counter()
    for part in parts:
        total.update(json.loads((part.schema.metadata or {}).get(ASSUMED_KEY, b"{}")))
    return dict(total)


def _finish(root: Path, spec: QuerySpec, status: str, parts: Path, planned: Plan, vocabulary: Vocabulary) -> Results:
    """Gather the parts and the pruned traces into the results, with the warnings for the names the
    query uses that no trace has (classes from the catalog, image channels from the parts); write
    them out and to the catalog."""
    tables = [pq.read_table(p) for p in sorted(parts.glob("*.parquet"))]
    for part in tables:
        vocabulary.add_channels(json.loads((part.schema.metadata or {}).get(CHANNELS_KEY, b"[]")))
    pruned = [{**identity_of(row), **pruned_row(reason)} for row, reason in planned.pruned]
    table = pa.concat_tables([results_table(pruned), *(t.replace_schema_metadata(None) for t in tables)])
    run_id = run_id_of(spec)
    warnings = query_warnings(spec, compiled(spec), vocabulary)
    results = Results(table.sort_by(ORDER), run_id, status, spec.key(), _assumed(tables), warnings)
    results.write_parquet(root / "runs" / run_id / RESULTS_FILE)
    with Catalog(root) as catalog:
        catalog.finish_run(run_id, status, table, results.counts())
    return results
