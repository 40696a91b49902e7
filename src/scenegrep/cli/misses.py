"""Nearest misses on the command line: when a Scenic query matches nothing, the frames that the
smallest raised tolerances would admit (:mod:`scenegrep.scene.misses`), one line each on stderr
and, with ``--json``, one ``{"nearest_miss": true, ...}`` record each on stdout."""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from ..scene.misses import MissLimits, NearestMisses

SceneAt = Callable[[], tuple[Any, np.ndarray | None]]
"""Builds a trace's scene result and the frame positions to examine (None: all), when needed."""


class MissCollector:
    """The first ``limits.traces`` traces of a run, kept until the run ends without a match;
    ``what`` starts each miss's line."""

    def __init__(self, what: str = "nearest miss", limits: MissLimits | None = None):
        self.what = what
        self.limits = limits or MissLimits()
        self.pending: list[tuple[str, SceneAt]] = []
        self.seen = 0

    def offer(self, source: str, scene_at: SceneAt) -> None:
        """A trace (by the label its output lines use) and how to get its scene result."""
        self.seen += 1
        if len(self.pending) < self.limits.traces:
            self.pending.append((source, scene_at))

    def report(self, as_json: bool) -> None:
        """Search the kept traces and print the nearest misses and what was examined."""
        misses = NearestMisses(self.limits, skipped=self.seen - len(self.pending))
        for source, scene_at in self.pending:
            misses.add(*scene_at(), source)
        print_misses(misses, self.what, as_json)


def print_misses(misses: NearestMisses, what: str, as_json: bool) -> None:
    """Each miss on stderr as ``scenegrep: WHAT: ...`` (and as a JSON record on stdout with
    ``as_json``), then what was examined."""
    for miss in misses.found:
        print(f"scenegrep: {what}: {miss.text()}", file=sys.stderr)
        if as_json:
            sys.stdout.write(json.dumps(miss.record()) + "\n")
    print(f"scenegrep: {misses.summary()}", file=sys.stderr)


def what_of(kind: str) -> str:
    """How a miss's line starts for a query kind."""
    return "nearest miss of the initial scene" if kind == "scenario" else "nearest miss"
