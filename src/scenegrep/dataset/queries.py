"""The three query kinds as the dataset engine sees them: a picklable :class:`QuerySpec`,
compiled once per process, applied to one trace to give rows of the results table.

Results table (one row per match; a trace without a match has one row with ``match`` -1; a
scene query with ``explain`` has a 'no match' row for each frame that does not match, saying why):
``trace_id``, ``name`` (the trace's name), ``source`` (the ingested input), ``status``
('match', 'no match', 'pruned' or 'failed'), ``match`` (0, 1, ... within the trace),
``correspondence`` (JSON object: program object -> trace object id; for SpRE, the track
binders' variables), ``start_frame``/``end_frame`` (dataset frame indices of the window's first
and last frame, inclusive), ``start_time``/``end_time`` (seconds from the trace's start),
``time_origin_ns`` (the trace's absolute time 0), ``explanation`` (with ``explain``: the
witness of a match or why the trace does not match; for pruned traces, why), ``error``, and
``values`` (scene matches with ``values``: JSON object of the program's random variables' values
that reproduce the frame, and each soft requirement's truth), ``intervals`` (scene matches, and
the initial scene of scenario matches, with ``intervals``: JSON object of every value of each
random variable that reproduces the (first) frame, as intervals; see
:meth:`scenegrep.scene.projection.FrameValues.to_json`), and ``objects`` (JSON object,
program object -> ``{"id", "start_frame", "end_frame", "start_time", "end_time"}``: the labeled
object it corresponds to and the frames, inclusive, and times (s) in which it is involved; see
:func:`involvement`).

One trace's rows come from :func:`query_trace` whether the trace was ingested (a dataset run)
or read from a file (:mod:`scenegrep.dataset.files`).
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any, TypeVar

import pyarrow as pa

from ..errors import UserError, failure_text
from ..model import LabelTrace, RoadMap

KINDS = ("scenario", "scene", "spre")

T = TypeVar("T")

RESULTS_SCHEMA = pa.schema(
    [
        ("trace_id", pa.string()),
        ("name", pa.string()),
        ("source", pa.string()),
        ("status", pa.string()),
        ("match", pa.int32()),
        ("correspondence", pa.string()),
        ("start_frame", pa.int64()),
        ("end_frame", pa.int64()),
        ("start_time", pa.float64()),
        ("end_time", pa.float64()),
        ("time_origin_ns", pa.int64()),
        ("explanation", pa.string()),
        ("error", pa.string()),
        ("values", pa.string()),
        ("objects", pa.string()),
        ("intervals", pa.string()),
    ]
)

ORDER = [("trace_id", "ascending"), ("match", "ascending"), ("start_frame", "ascending")]
"""The order of a results table's rows."""

OPTIONS: dict[str, dict[str, Any]] = {
    "scenario": {
        "window": None,
        "tolerance_profile": None,
        "tolerance_position": None,
        "tolerance_heading": None,
        "tolerance_speed": None,
        "visible_distance": None,
        "vocabulary": None,
        "all": False,
        "explain": False,
        "intervals": False,
        "unknown_layers": None,
    },
    "scene": {
        "tolerance_profile": None,
        "tolerance_position": None,
        "tolerance_heading": None,
        "tolerance_speed": None,
        "visible_distance": None,
        "exact": False,
        "explain": False,
        "values": False,
        "intervals": False,
        "unknown_layers": None,
    },
    "spre": {"compat": False, "space": None, "channels": None, "skip": 0},
}
"""Each kind's options and their defaults (the command-line options of the same names); a
tolerance that is None takes the value of ``tolerance_profile`` (None: exact)."""


@dataclass(frozen=True)
class QuerySpec:
    """A query as data: its ``kind``, its ``text`` (a Scenic program or a SpRE), the ``origin``
    its errors name (a file name) and its options as sorted (name, value) pairs."""

    kind: str
    text: str
    origin: str
    options: tuple[tuple[str, Any], ...]

    @classmethod
    def of(cls, kind: str, text: str, origin: str = "<query>", **options: Any) -> QuerySpec:
        """A spec with ``options`` checked against the kind's and completed with defaults."""
        if kind not in KINDS:
            raise UserError(f"unknown query kind {kind!r}; choose one of {', '.join(KINDS)}")
        unknown = set(options) - set(OPTIONS[kind])
        if unknown:
            raise UserError(f"{kind} queries have no option {sorted(unknown)[0]!r}")
        merged = OPTIONS[kind] | {k: _plain(v) for k, v in options.items()}
        if kind == "scenario" and merged["window"] is None:
            raise UserError("scenario queries need a window (frames, seconds such as '5s', or 'all')")
        spec = cls(kind, text, origin, tuple(sorted(merged.items())))
        if kind != "spre":
            spec_tolerance(spec)
            spec_choice(spec)
        return spec

    @classmethod
    def from_file(cls, kind: str, path: str | Path, **options: Any) -> QuerySpec:
        """A spec whose text is a Scenic program file."""
        from ..scenic.parser import read_program

        return cls.of(kind, read_program(path), str(path), **options)

    def option(self, name: str) -> Any:
        return dict(self.options)[name]

    def key(self) -> str:
        """A canonical JSON text of the spec (a run's identity)."""
        return json.dumps([self.kind, self.text, dict(self.options)], sort_keys=True)


def _plain(value: Any) -> Any:
    """Options as JSON-able, hashable values (lists become tuples)."""
    return tuple(value) if isinstance(value, list) else value


_COMPILED: dict[QuerySpec, Any] = {}


def compiled(spec: QuerySpec) -> Any:
    """The compiled query of a spec, compiled once per process (UserError if it does not compile)."""
    if spec not in _COMPILED:
        _COMPILED[spec] = _compile(spec)
    return _COMPILED[spec]


def _compile(spec: QuerySpec) -> Any:
    if spec.kind == "spre":
        from ..spre import compile_query

        return compile_query(spec.text, compat=spec.option("compat"), source=spec.origin)
    if spec.kind == "scene":
        from ..scene import compile_scene

        return compile_scene(spec.text, spec.origin, spec.option("visible_distance"))
    from ..scenario import compile_scenario, load_vocabulary

    vocabulary = load_vocabulary(spec.option("vocabulary"))
    return compile_scenario(spec.text, spec.origin, vocabulary, spec.option("visible_distance"))


def spec_tolerance(spec: QuerySpec) -> Any:
    """The spec's tolerances: its profile's, each given tolerance instead (checked when the spec was made)."""
    from ..scene.profiles import tolerance_of

    return tolerance_of(
        spec.option("tolerance_profile"),
        position=spec.option("tolerance_position"),
        heading=spec.option("tolerance_heading"),
        speed=spec.option("tolerance_speed"),
    )


def match_trace(spec: QuerySpec, trace: LabelTrace, road_map: RoadMap | None) -> list[dict[str, Any]]:
    """The result rows of one trace (without its trace_id, name, source and time origin), at
    least one: a trace without a match gives one 'no match' row."""
    runner = {"spre": _spre_rows, "scene": _scene_rows, "scenario": _scenario_rows}[spec.kind]
    rows = runner(spec, compiled(spec), trace, road_map)
    return rows or [{"status": "no match", "match": -1}]


def _window(trace: LabelTrace, match: int, first: int, last: int, correspondence: Any) -> dict[str, Any]:
    """A match row: frames at positions first..last (inclusive) of ``trace``."""
    span = _span(trace, first, last)
    return {
        "status": "match",
        "match": match,
        "correspondence": json.dumps(correspondence or {}, sort_keys=True),
        **span,
        "objects": json.dumps(involvement(correspondence or {}, span)),
    }


def involvement(correspondence: dict[str, Any], span: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Each program object of a match -> the labeled object it
    corresponds to (``id``) and the frames and times in which it is involved: the match's
    whole ``span`` (frame-range columns) for every kind of query. A scenario window requires
    every corresponded object in each of its frames, a scene match is one frame, and a SpRE's
    track binder names the object whose instantiation matches the whole stretch (the SpRE
    engine does not say in which frames the binder's sub-expression held)."""
    return {str(name): {"id": str(label), **span} for name, label in correspondence.items()}


def _span(trace: LabelTrace, first: int, last: int) -> dict[str, Any]:
    """The frame-range columns of frames at positions first..last (inclusive): their dataset
    frame indices and their times (s, to 1 ns as in JSON Lines: :mod:`scenegrep.json_lines`)."""
    from ..json_lines import TIME_DECIMALS

    return {
        "start_frame": int(trace.frame_index[first]),
        "end_frame": int(trace.frame_index[last]),
        "start_time": round(float(trace.frame_time[first]), TIME_DECIMALS) + 0.0,
        "end_time": round(float(trace.frame_time[last]), TIME_DECIMALS) + 0.0,
    }


def _spre_rows(spec: QuerySpec, query: Any, trace: LabelTrace, road_map: RoadMap | None) -> list[dict[str, Any]]:
    from ..spre import SearchOptions, TraceSearch

    options = SearchOptions(spec.option("space"), spec.option("channels"), max(spec.option("skip"), 0))
    search = TraceSearch(query, trace, options)
    searched = search.trace
    rows = []
    for number, match in enumerate(search.offline()):
        row = _window(searched, number, match.start, match.end - 1, match.bound)
        rows.append(row)
    return rows


def spec_choice(spec: QuerySpec) -> Any:
    """The spec's choice for unknown map layers (checked when the spec was made), one object per
    choice and process, so the road-map geometry built for it serves every trace on the same map;
    its decision counts are the process's (:func:`decisions_while` takes one run's out of them)."""
    return _choice_of(spec.option("unknown_layers"))


def decisions_while(spec: QuerySpec, action: Callable[[], T]) -> tuple[T, dict[str, int]]:
    """``action()``'s result and, per layer, the decisions the spec's choice for unknown map layers
    counted while it ran (none for a SpRE, which reads no map): this process's part of a run."""
    counts: Counter[str] = spec_choice(spec).decisions if uses_map(spec) else Counter()
    before = Counter(counts)
    result = action()
    return result, dict(counts - before)


@cache
def _choice_of(mode: str | None) -> Any:
    from ..model.layers import UnknownLayers

    return UnknownLayers(mode)


def scene_options(spec: QuerySpec) -> Any:
    """The :class:`~scenegrep.scene.SceneOptions` of a scene spec."""
    from ..scene import SceneOptions

    return SceneOptions(
        spec_tolerance(spec), spec.option("exact"), spec.option("visible_distance"), unknown_layers=spec_choice(spec)
    )


def scenario_options(spec: QuerySpec) -> Any:
    """The :class:`~scenegrep.scenario.ScenarioOptions` of a scenario spec."""
    from ..scenario import ScenarioOptions

    return ScenarioOptions(
        spec_tolerance(spec), spec.option("visible_distance"), spec.option("all"), unknown_layers=spec_choice(spec)
    )


def _scene_rows(spec: QuerySpec, query: Any, trace: LabelTrace, road_map: RoadMap | None) -> list[dict[str, Any]]:
    result = query.match(trace, road_map, scene_options(spec))
    rows = []
    for number, frame in enumerate(result.frames().tolist()):
        row = _window(trace, number, frame, frame, result.correspondence(frame))
        if spec.option("values"):
            soft = {name: bool(holds[number]) for name, holds in result.soft.items()}
            row["values"] = json.dumps(result.values(frame) | soft, allow_nan=True)
        if spec.option("intervals"):
            row["intervals"] = json.dumps(result.recovered[number].to_json(), allow_nan=True)
        rows.append(row)
    if spec.option("explain"):
        rows.extend(
            {"status": "no match", "match": -1, **_span(trace, f, f), "explanation": result.failure(f)}
            for f in (~result.matched).nonzero()[0].tolist()
        )
    return rows


def _scenario_rows(spec: QuerySpec, query: Any, trace: LabelTrace, road_map: RoadMap | None) -> list[dict[str, Any]]:
    if trace.behaviours is None:
        from ..label import label_trace

        trace = label_trace(trace, road_map, unknown_layers=spec_choice(spec)).trace
    result = query.match(trace, spec.option("window"), road_map, scenario_options(spec))
    return scenario_rows(result, spec.option("all"), spec.option("explain"), spec.option("intervals"))


def scenario_rows(result: Any, find_all: bool, explain: bool, intervals: bool = False) -> list[dict[str, Any]]:
    """The rows of a scenario query's result on one trace (empty: no match, unless ``explain``):
    every window with ``find_all``, else the first; with ``intervals``, the recovered values of
    each window's initial scene."""
    trace = result.trace
    rows = []
    scenes: dict[int, dict[int, Any]] = {}
    for number, (match, first, last) in enumerate(result.windows()):
        row = _window(trace, number, first, last, match.correspondence)
        if explain:
            row["explanation"] = "\n".join(result.explain(result.matches.index(match), first))
        if intervals:
            index = result.matches.index(match)
            if index not in scenes:
                scene = result.initial_scene(index)
                scenes[index] = dict(zip(scene.frames().tolist(), scene.recovered))
            row["intervals"] = json.dumps(scenes[index][first].to_json(), allow_nan=True)
        rows.append(row)
        if not find_all:
            break
    if not rows and explain:
        return [{"status": "no match", "match": -1, "explanation": result.why_not()}]
    return rows


def query_trace(identity: dict[str, Any], where: str, rows: Callable[[], list[dict[str, Any]]]) -> list[dict[str, Any]]:
    """One trace's result rows, each with the trace's ``identity`` (trace_id, name, source,
    time_origin_ns): ``rows()`` loads and queries the trace; if it raises, the trace gets one
    'failed' row whose error names ``where``, and the caller goes on with the next trace."""
    try:
        found = rows()
    except Exception as exc:  # one broken trace must not stop the others
        found = [{"status": "failed", "match": -1, "error": failure_text(exc, where)}]
    return [{**identity, **row} for row in found]


def pruned_row(reason: str) -> dict[str, Any]:
    """The row of a trace the planner pruned (it cannot match), with the reason."""
    return {"status": "pruned", "match": -1, "explanation": reason}


@dataclass(frozen=True)
class TraceTask:
    """One trace to query: its catalog identity, its Parquet file and its map's (absolute paths),
    and the choice for unknown map layers ingest labelled it under (:mod:`.labelling`)."""

    trace_id: str
    name: str
    source: str
    file: str
    map_file: str | None
    time_origin_ns: int
    labelled_under: str | None = None


@dataclass(frozen=True)
class ChunkRows:
    """What a worker sends back for a chunk of traces: their ``rows``, per map layer the
    decisions the choice for unknown layers affected (``assumed``), and the image ``channels``
    of the traces it read, for the run's report."""

    rows: list[dict[str, Any]]
    assumed: dict[str, int]
    channels: tuple[str, ...] = ()


def run_tasks(work: tuple[QuerySpec, str | None, list[TraceTask]]) -> ChunkRows:
    """Query a chunk of traces (runs in a worker): ``work`` is the spec, a fallback map path for
    traces without one, and the tasks. A trace that fails to load or query gives a 'failed' row."""
    spec, fallback_map, tasks = work
    channels: set[str] = set()
    rows, assumed = decisions_while(
        spec, lambda: [row for task in tasks for row in _query_task(spec, task, fallback_map, channels)]
    )
    return ChunkRows(rows, assumed, tuple(sorted(channels)))


def _query_task(spec: QuerySpec, task: TraceTask, fallback_map: str | None, channels: set[str]) -> list[dict[str, Any]]:
    """One task's rows (:func:`query_trace`); the trace's image channels go into ``channels``."""
    identity = {
        "trace_id": task.trace_id,
        "name": task.name,
        "source": task.source,
        "time_origin_ns": task.time_origin_ns,
    }
    return query_trace(identity, task.file, lambda: _task_rows(spec, task, fallback_map, channels))


def _task_rows(spec: QuerySpec, task: TraceTask, fallback_map: str | None, channels: set[str]) -> list[dict[str, Any]]:
    """One ingested trace's rows; a scenario query reads its labels under the query's choice for
    unknown map layers, labelled on its map as a query over files labels it (:func:`.labelling.labelled`);
    its map is its own, else ``fallback_map`` (:func:`scenegrep.readers.with_given_map`)."""
    from .. import readers
    from .labelling import labelled

    trace = readers.read_trace(task.file, "scenegrep-parquet")
    if trace.images is not None:
        channels.update(trace.images.samples.channels)
    if not uses_map(spec):
        return match_trace(spec, trace, None)
    if task.map_file and fallback_map:
        raise readers.map_conflict(task.name, task.map_file)
    road_map = readers.read_map(task.map_file or fallback_map) if task.map_file or fallback_map else None
    if spec.kind == "scenario":
        trace = labelled(trace, road_map, spec_choice(spec), task.labelled_under)
    return match_trace(spec, trace, road_map)


def uses_map(spec: QuerySpec) -> bool:
    """Whether the query reads road maps (Scenic queries do; a SpRE never reads one)."""
    return spec.kind != "spre"


def results_table(rows: list[dict[str, Any]]) -> pa.Table:
    """Rows (dicts with some of the columns) as a table of :data:`RESULTS_SCHEMA`."""
    return pa.Table.from_pylist(rows, schema=RESULTS_SCHEMA)
