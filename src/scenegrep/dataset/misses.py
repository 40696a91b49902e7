"""Nearest misses of a Scenic query's run that matched nothing: the traces of its 'no match'
rows, read back, searched by :class:`scenegrep.scene.misses.NearestMisses` (a scene query over
every frame, a scenario query's initial scene over its window starts)."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError
from ..model import LabelTrace, RoadMap
from ..scene.misses import MissLimits, NearestMisses
from .files import read_queried_trace
from .queries import QuerySpec, compiled, scenario_options, scene_options
from .results import Results
from .traces import load_trace

Loader = Callable[[str], tuple[LabelTrace, RoadMap | None]]
"""A trace of the run and its road map, by trace id."""


def scene_result(spec: QuerySpec, trace: LabelTrace, road_map: RoadMap | None) -> tuple[Any, np.ndarray | None]:
    """The scene result a Scenic spec's nearest misses are searched in on one trace, and the
    frame positions to search (None: all)."""
    query = compiled(spec)
    if spec.kind == "scene":
        return query.match(trace, road_map, scene_options(spec)), None
    return query.initial_scene(trace, spec.option("window"), road_map, scenario_options(spec))


def nearest_misses(
    spec: QuerySpec, rows: list[dict[str, Any]], load: Loader, limits: MissLimits | None = None
) -> NearestMisses:
    """The nearest misses over the traces of a run's 'no match' rows (the first ``limits.traces``
    of them, in order; a trace that no longer loads is counted as not examined)."""
    limits = limits or MissLimits()
    sources = {row["trace_id"]: row["source"] for row in rows if row["status"] == "no match"}
    misses = NearestMisses(limits, skipped=max(len(sources) - limits.traces, 0))
    for trace_id in list(sources)[: limits.traces]:
        try:
            trace, road_map = load(trace_id)
        except UserError:
            misses.skipped += 1
            continue
        misses.add(*scene_result(spec, trace, road_map), sources[trace_id])
    return misses


def misses_of_results(
    spec: QuerySpec,
    results: Results,
    dataset: str | Path | None = None,
    map_path: str | None = None,
    limits: MissLimits | None = None,
) -> NearestMisses:
    """The nearest misses of ``results``, what the Scenic query ``spec`` (kind 'scene' or
    'scenario') gave: its first traces without a match (:func:`nearest_misses`), read again from
    the dataset at ``dataset`` (the results of a run over it), or, without one, from the files the
    rows name (a query over files) on their own map, else ``map_path``'s, labelled under the spec's
    choice for unknown map layers. A trace that no longer loads is counted as not examined."""
    rows = results.table.to_pylist()
    if dataset is not None:
        load: Loader = partial(load_trace, Path(dataset).resolve())
    else:
        load = partial(_file_trace, {row["trace_id"]: row["source"] for row in rows}, map_path, spec)
    return nearest_misses(spec, rows, load, limits)


def _file_trace(
    sources: dict[str, str], map_path: str | None, spec: QuerySpec, trace_id: str
) -> tuple[LabelTrace, RoadMap | None]:
    """A trace of a query over files, read again from the file its rows name."""
    return read_queried_trace(sources[trace_id], trace_id, map_path, spec.option("unknown_layers"))
