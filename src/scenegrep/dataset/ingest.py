"""``ingest``: turn inputs of any supported format into a dataset directory.

Layout: ``catalog.duckdb`` (:mod:`.catalog`), ``traces/<trace_id>.parquet`` (scenegrep
Parquet traces), ``maps/<map_id>.parquet`` (their road maps, converted once per map), and
``runs/`` (query runs). Sources are files or directories the readers recognise; a directory
that is not itself an input is searched for inputs, in name order.

Ingest is incremental (a source whose SHA-256 is in the catalog is skipped, unless its traces
were labelled by another version of the labeller, :data:`~scenegrep.label.LABELLER_VERSION`),
atomic per trace (each Parquet file appears whole, by rename, before the catalog commits the trace;
a source's traces are committed together) and reports bad sources without stopping.
Traces without behaviour labels are labelled with ``scenegrep label``'s labeller unless
``label`` is False, so scenario queries under the same choice for unknown map layers need no
labelling later; the catalog records the choice each trace was labelled under
(:mod:`.labelling`), and a query under another choice labels the trace again.
"""

from __future__ import annotations

import hashlib
import os
import re
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import readers
from ..errors import UserError, at, failure_text
from ..model import LabelTrace, RoadMap
from ..model.layers import UnknownLayers
from .catalog import Catalog
from .execute import run_all
from .labelling import COLUMN, labelled, recorded_choice
from .statistics import TraceStatistics
from ..wording import article

COMMIT_EVERY = 16
"""Sources committed to the catalog per transaction (each trace is atomic either way)."""

TRACES_DIR = "traces"
MAPS_DIR = "maps"


@dataclass(frozen=True)
class Source:
    """An input to ingest: its absolute path and format name."""

    path: str
    format: str


@dataclass(frozen=True)
class IngestTask:
    """What a worker needs to ingest one source: it, the dataset root, the checksum the
    catalog has for it (None if new), whether to label traces without behaviour labels, and the
    labeller's choice for map layers a map does not publish (see :mod:`scenegrep.model.layers`), and
    the road map of traces without one (``--map``, :func:`scenegrep.readers.with_given_map`)."""

    source: Source
    root: str
    known_checksum: str | None
    label: bool
    unknown_layers: str | None = None
    map_path: str | None = None


@dataclass
class SourceOutcome:
    """What became of one source: ``status`` 'ingested', 'unchanged' or 'failed', its checksum,
    the trace and map rows written (with their statistics), or the error."""

    source: Source
    status: str
    checksum: str = ""
    replaces: bool = False
    """Whether the catalog had an older version of the source."""
    traces: list[tuple[dict[str, Any], TraceStatistics]] = field(default_factory=list)
    maps: list[dict[str, Any]] = field(default_factory=list)
    error: str = ""
    assumed: Counter[str] = field(default_factory=Counter)
    """Labelling decisions the choice for unknown map layers affected, per layer."""


@dataclass
class IngestReport:
    """Counts of an ingest run, the failed sources (path, one-line error) and the labelling
    decisions the choice for unknown map layers affected, per layer."""

    ingested: int = 0
    unchanged: int = 0
    traces: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    assumed: Counter[str] = field(default_factory=Counter)


def discover(paths: list[str]) -> tuple[list[Source], list[tuple[str, str]]]:
    """The sources under ``paths`` and the paths that are not inputs or cannot be read (path,
    error): a given path, or a file in a searched directory that looks like an input but is
    unreadable (a truncated Parquet file); the other files are still found.

    Directories that are not inputs are searched recursively; files found there that are not
    trace inputs (READMEs, manifests, map-only files) are skipped silently, and so are JSON files
    that are not scenegrep traces, as in a trace folder (give STREM streams by name)."""
    sources: list[Source] = []
    errors: list[tuple[str, str]] = []
    for path in paths:
        _collect(Path(path), True, sources, errors)
    unique = {s.path: s for s in sources}
    return list(unique.values()), errors


def _collect(path: Path, explicit: bool, sources: list[Source], errors: list[tuple[str, str]]) -> None:
    """Add the sources at ``path`` (a given path when ``explicit``, else one found in a directory)."""
    try:
        if path.is_dir():
            found = directory_format(path)
            if found is not None:
                sources.append(Source(str(path.resolve()), found))
                return
            for child in sorted(path.iterdir()):
                if not child.name.startswith("."):
                    _collect(child, False, sources, errors)
            return
        name = _file_format(path, explicit)
        if name is not None:
            sources.append(Source(str(path.resolve()), name))
    except UserError as exc:
        errors.append((str(path.resolve()), exc.one_line()))


def _file_format(path: Path, explicit: bool) -> str | None:
    """The trace format of a file: a given file must be one; a found one is skipped (None) if not."""
    if explicit:
        name = readers.detect_format(path)
        if not readers.FORMATS[name].traces:
            description = readers.FORMATS[name].description
            raise UserError(f"{article(description)} {description} holds no label trace", at(path))
        return name
    name = readers.sniff_file(path)
    return name if name is not None and name not in readers.SKIPPED and readers.FORMATS[name].traces else None


def directory_format(path: Path) -> str | None:
    """The format of a directory that is one input (an Argoverse 2 log or scenario), else None."""
    try:
        name = readers.detect_format(path)
    except UserError:
        return None
    return None if name == "trace-folder" else name


def checksum(path: str) -> str:
    """SHA-256 of a file's bytes, or of a directory's relative file names and bytes in name order."""
    root = Path(path)
    digest = hashlib.sha256()
    files = [root] if root.is_file() else sorted(p for p in root.rglob("*") if p.is_file())
    for file in files:
        if file != root:
            digest.update(str(file.relative_to(root)).encode() + b"\0")
        with open(file, "rb") as handle:
            digest.update(hashlib.file_digest(handle, "sha256").digest())
    return digest.hexdigest()


def source_key(path: str, label: bool, map_path: str | None = None) -> str:
    """What the catalog keeps to tell an unchanged source: its :func:`checksum`, when ingest
    labels its traces the labeller's version (labels of an older labeller are not reused), and
    the checksum of a ``--map`` (traces ingested with another map are not reused)."""
    from ..label import LABELLER_VERSION

    digest = checksum(path)
    if label:
        digest = f"{digest} labeller {LABELLER_VERSION}"
    return digest if map_path is None else f"{digest} map {checksum(map_path)}"


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:64] or "trace"


def trace_id_of(source_path: str, name: str, number: int) -> str:
    """A trace's id: its name made file-safe, and a hash of its source path and position."""
    tag = hashlib.sha256(f"{source_path}\0{number}\0{name}".encode()).hexdigest()[:10]
    return f"{_slug(name)}-{tag}"


def map_id_of(map_source: Any) -> str:
    """A road map's id: a hash of where it is read from."""
    return hashlib.sha256(repr((map_source.path, map_source.format, map_source.key)).encode()).hexdigest()[:16]


def ingest_source(task: IngestTask) -> SourceOutcome:
    """Ingest one source (runs in a worker): skip it if unchanged, else write its traces and
    maps and compute their statistics. Any failure becomes a 'failed' outcome."""
    source = task.source
    try:
        digest = source_key(source.path, task.label, task.map_path)
        if digest == task.known_checksum:
            return SourceOutcome(source, "unchanged", digest)
        outcome = SourceOutcome(source, "ingested", digest, replaces=task.known_checksum is not None)
        choice = UnknownLayers(task.unknown_layers)
        for number, trace in enumerate(readers.read_traces(source.path, source.format)):
            outcome.traces.append(_write_trace(trace, number, task, outcome.maps, choice))
        outcome.assumed = choice.decisions
        return outcome
    except Exception as exc:  # a bad source, or a reader's bug, must not stop the other sources
        return SourceOutcome(source, "failed", error=failure_text(exc, source.path))


def prepare_trace(
    trace: LabelTrace, label: bool, unknown_layers: UnknownLayers | None = None, map_path: str | None = None
) -> tuple[LabelTrace, RoadMap | None]:
    """A trace as a dataset holds it, and its road map (None when it has none): its own, or
    ``map_path`` (``--map``) when it names none (:func:`scenegrep.readers.with_given_map`: a
    trace naming its own map and a ``map_path`` is a UserError); when ``label`` and it has no
    behaviour labels, labelled with that map by ``scenegrep label``'s labeller, under the choice
    ``unknown_layers`` for map layers the map does not publish. Ingest and a query over files both
    read traces this way."""
    trace = readers.with_given_map(trace, map_path)
    road_map = None if trace.map_source is None else readers.read_map(trace.map_source)
    if label:
        trace = labelled(trace, road_map, unknown_layers)
    return trace, road_map


def catalog_row(
    trace: LabelTrace,
    trace_id: str,
    source_path: str,
    file: str,
    map_id: str | None,
    labelled_under: str | None = None,
) -> tuple[dict[str, Any], TraceStatistics]:
    """A trace's ``traces`` row in the catalog and its statistics; ``labelled_under`` is the
    choice ingest labelled it under (:mod:`.labelling`; None: ingest did not label it)."""
    stats = TraceStatistics.of(trace)
    row = {"trace_id": trace_id, **stats.trace, "source_path": source_path, "file": file, "map_id": map_id}
    return row | {COLUMN: labelled_under}, stats


def labelling_choice(trace: LabelTrace, label: bool, choice: UnknownLayers) -> str | None:
    """The choice ingest labels ``trace`` under, as the catalog records it: None when it does not
    label it (its labels are its own, or ``label`` is False)."""
    return recorded_choice(choice.mode) if label and trace.behaviours is None else None


def _write_trace(
    trace: LabelTrace, number: int, task: IngestTask, maps: list[dict[str, Any]], choice: UnknownLayers
) -> tuple[dict, Any]:
    from ..writers.trace_parquet import write_map_parquet, write_trace_parquet

    root = Path(task.root)
    recorded = labelling_choice(trace, task.label, choice)
    trace, road_map = prepare_trace(trace, task.label, choice, task.map_path)
    map_id = None
    if road_map is not None:
        ms = trace.map_source
        map_id = map_id_of(ms)
        map_file = f"{MAPS_DIR}/{map_id}.parquet"
        if not (root / map_file).is_file():
            write_map_parquet(road_map, root / map_file)
        maps.append({"map_id": map_id, "file": map_file, "source_path": ms.path, "format": ms.format, "key": ms.key})
    trace_id = trace_id_of(task.source.path, trace.name, number)
    file = f"{TRACES_DIR}/{trace_id}.parquet"
    write_trace_parquet(trace, root / file)
    return catalog_row(trace, trace_id, task.source.path, file, map_id, recorded)


def _remove_stale_temporaries(root: Path) -> None:
    """Delete the temporary files a killed ingest left (atomic writes never expose them)."""
    for folder in (root / TRACES_DIR, root / MAPS_DIR):
        if folder.is_dir():
            for tmp in folder.glob(".*.tmp"):
                tmp.unlink(missing_ok=True)


def ingest(
    paths: list[str],
    into: str | Path,
    jobs: int | None = None,
    label: bool = True,
    on_outcome: Callable[[SourceOutcome], None] | None = None,
    unknown_layers: str | None = None,
    map_path: str | None = None,
) -> IngestReport:
    """Ingest every source under ``paths`` into the dataset ``into`` (created if needed) with
    ``jobs`` local workers; ``on_outcome`` sees each source's outcome as it is committed;
    ``unknown_layers`` is the labeller's choice for map layers a map does not publish;
    ``map_path`` the road map of traces without one (:func:`scenegrep.readers.with_given_map`)."""
    UnknownLayers(unknown_layers)
    if map_path is not None:
        map_path = readers.given_map_source(map_path).path
    root = Path(into).resolve()
    sources, bad = discover(paths)
    with Catalog(root, create=True) as catalog:
        known = catalog.checksums()
        for path, error in bad:
            catalog.record_source_error(path, error)
    _remove_stale_temporaries(root)
    tasks = [IngestTask(s, str(root), known.get(s.path), label, unknown_layers, map_path) for s in sources]
    report = IngestReport(failed=list(bad))
    results = run_all(ingest_source, tasks, jobs)
    batch: list[SourceOutcome] = []
    with Catalog(root) as catalog:
        for _, outcome in results:
            batch.append(outcome)
            if len(batch) >= COMMIT_EVERY:
                _commit(catalog, root, batch, report)
                batch = []
            if on_outcome is not None:
                on_outcome(outcome)
        _commit(catalog, root, batch, report)
    return report


def _commit(catalog: Catalog, root: Path, batch: list[SourceOutcome], report: IngestReport) -> None:
    """Record a batch of outcomes in one transaction; then delete trace files no trace uses."""
    ingested = [o for o in batch if o.status == "ingested"]
    report.unchanged += sum(o.status == "unchanged" for o in batch)
    for outcome in batch:
        if outcome.status == "failed":
            catalog.record_source_error(outcome.source.path, outcome.error)
            report.failed.append((outcome.source.path, outcome.error))
    maps = {row["map_id"]: row for o in ingested for row in o.maps}
    for row in maps.values():
        catalog.add_map(row)
    old_files = {f for o in ingested if o.replaces for f in catalog.trace_files(o.source.path)}
    catalog.replace_sources(
        [({"path": o.source.path, "format": o.source.format, "checksum": o.checksum}, o.traces) for o in ingested]
    )
    for stale in old_files - {row["file"] for o in ingested for row, _ in o.traces}:
        os.unlink(root / stale)
    for outcome in ingested:
        report.assumed.update(outcome.assumed)
    report.ingested += len(ingested)
    report.traces += sum(len(o.traces) for o in ingested)
