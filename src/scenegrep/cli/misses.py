"""Nearest misses on the command line: when a Scenic query matches nothing, the frames that the
smallest raised tolerances would admit (:mod:`scenegrep.dataset.misses`), one line each on stderr
and, with ``--json``, one ``{"nearest_miss": true, ...}`` record each on stdout."""

from __future__ import annotations

import sys

from ..json_lines import write
from ..scene.misses import NearestMisses


def print_misses(misses: NearestMisses, what: str, as_json: bool) -> None:
    """Each miss on stderr as ``scenegrep: WHAT: ...`` (and as a JSON record on stdout with
    ``as_json``), then what was examined."""
    for miss in misses.found:
        print(f"scenegrep: {what}: {miss.text()}", file=sys.stderr)
        if as_json:
            write(miss.record())
    print(f"scenegrep: {misses.summary()}", file=sys.stderr)


def what_of(kind: str) -> str:
    """How a miss's line starts for a query kind."""
    return "nearest miss of the initial scene" if kind == "scenario" else "nearest miss"
