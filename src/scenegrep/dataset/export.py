"""Matches as Foxglove events in an MCAP file, so they open in Foxglove at the right moment.

Each match row of a results table becomes one message on the topic ``/scenegrep/matches``
with the ``foxglove.Event`` schema (JSON encoding): ``start_time`` and ``end_time`` are the
window's first and last frame as absolute times (the trace's ``time_origin_ns`` plus the
frame's time; traces without an origin start at 0), ``metadata`` key-value pairs name the
run, the trace, its source, the frame range and the program objects' labeled ids. The log
time of the message is the window's start.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from ..errors import UserError
from .results import Results

TOPIC = "/scenegrep/matches"

EVENT_SCHEMA = {
    "title": "foxglove.Event",
    "description": "A discrete event that occurred over a time range",
    "type": "object",
    "properties": {
        "start_time": {"$ref": "#/$defs/time", "description": "Event start time (inclusive)"},
        "end_time": {"$ref": "#/$defs/time", "description": "Event end time (inclusive)"},
        "metadata": {
            "type": "array",
            "items": {
                "title": "foxglove.KeyValuePair",
                "type": "object",
                "properties": {"key": {"type": "string"}, "value": {"type": "string"}},
                "required": ["key", "value"],
            },
        },
    },
    "required": ["start_time", "end_time"],
    "$defs": {
        "time": {
            "type": "object",
            "properties": {
                "sec": {"type": "integer", "minimum": 0},
                "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999},
            },
        }
    },
}


def absolute_ns(origin_ns: int, seconds: float) -> int:
    """A trace time (s from its start) as absolute nanoseconds, never before 0."""
    return max(0, int(origin_ns) + int(round(seconds * 1e9)))


def _time(ns: int) -> dict[str, int]:
    return {"sec": ns // 1_000_000_000, "nsec": ns % 1_000_000_000}


def event_of(row: dict[str, Any], run_id: str) -> tuple[int, dict[str, Any]]:
    """The (log time in ns, foxglove.Event message) of a match row; UserError for a row without
    times (a STREM stream's frames carry none)."""
    if not (math.isfinite(row["start_time"]) and math.isfinite(row["end_time"])):
        raise UserError(
            f"match {row['match']} of {row['name']}: the trace gives no time for its frames, and a Foxglove event "
            "needs its start and end time"
        )
    start = absolute_ns(row["time_origin_ns"] or 0, row["start_time"])
    end = absolute_ns(row["time_origin_ns"] or 0, row["end_time"])
    pairs = {
        "run_id": run_id,
        "trace": row["name"],
        "trace_id": row["trace_id"],
        "source": row["source"] or "",
        "match": str(row["match"]),
        "frames": f"{row['start_frame']}-{row['end_frame']}",
    }
    for name, label in json.loads(row["correspondence"] or "{}").items():
        pairs.setdefault(name, str(label))
    message = {
        "start_time": _time(start),
        "end_time": _time(end),
        "metadata": [{"key": k, "value": v} for k, v in pairs.items()],
    }
    return start, message


def write_mcap_events(results: Results, path: str | Path) -> int:
    """Write the matches of ``results`` as Foxglove events (atomically); returns how many."""
    from mcap.writer import Writer

    from ..writers.atomic import atomic_path

    events = sorted((event_of(row, results.run_id) for row in results.matches.to_pylist()), key=lambda e: e[0])
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        writer = Writer(handle)
        writer.start(profile="", library="scenegrep")
        schema = writer.register_schema("foxglove.Event", "jsonschema", json.dumps(EVENT_SCHEMA).encode())
        channel = writer.register_channel(TOPIC, "json", schema)
        for sequence, (log_time, message) in enumerate(events):
            writer.add_message(channel, log_time, json.dumps(message).encode(), log_time, sequence)
        writer.add_metadata("scenegrep", {"run_id": results.run_id, "status": results.status})
        writer.finish()
    return len(events)
