"""Nearest misses of a Scenic query's run that matched nothing: the traces of its 'no match'
rows, read back, searched by :class:`scenegrep.scene.misses.NearestMisses` (a scene query over
every frame, a scenario query's initial scene over its window starts)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import UserError
from ..model import LabelTrace, RoadMap
from ..scene.misses import MissLimits, NearestMisses
from .queries import QuerySpec, compiled, scenario_options, scene_options

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
