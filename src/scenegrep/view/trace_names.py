"""Which trace and match of a results table a user means (``show --trace NAME --match N``): every
name the command line prints for a trace is accepted.

A trace is named, in the order tried, by

1. its ``trace_id`` (the results' key, ``NAME-<hash>``);
2. its ``name``, when one trace of the table has it;
3. its source: the ``source`` path the results record, or any path to the same file (relative to
   the working directory), when one trace of the table came from it; or ``SOURCE#NAME`` (as the
   query commands print it, :mod:`scenegrep.dataset.places`), either path form;
4. any of these followed by ``:START-END`` (dataset frame indices): the trace and its match with
   that window. So a match line's ``SOURCE#NAME:START-END`` selects that match.

A name several traces share is an error listing them (``trace_id`` and source); an unknown name
is an error listing the table's traces, or the nearest ones when there are more than
:data:`LISTED`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..dataset.places import place
from ..errors import UserError, nearest
from ..wording import counted

LISTED = 10
"""An unknown name lists the table's traces up to this many, else the nearest names."""

_WINDOW = re.compile(r"(?P<name>.+):(?P<start>\d+)-(?P<end>\d+)")


@dataclass(frozen=True)
class TraceChoice:
    """The trace meant (``trace_id``) and, when the name gave ``:START-END``, that window's
    first and last dataset frame indices."""

    trace_id: str
    window: tuple[int, int] | None = None


@dataclass(frozen=True)
class _Trace:
    trace_id: str
    name: str
    source: str

    def names(self) -> set[str]:
        """The names that mean this trace (see the module docstring)."""
        names = {self.trace_id, self.name}
        if self.source:
            names |= {self.source, place(self.source, self.name)}
        return names

    def is_file(self, given: str) -> bool:
        """Whether ``given`` (a path, or ``PATH#NAME``) names this trace's source file (a path or
        a name may hold ``#``: ``PATH#NAME`` is told by its end, this trace's name)."""
        if not self.source:
            return False
        suffix = f"#{self.name}"
        if given.endswith(suffix) and _same_file(given[: -len(suffix)], self.source):
            return True
        return _same_file(given, self.source)

    def described(self) -> str:
        return f"{self.trace_id} ({self.source})" if self.source else self.trace_id


def choose_trace(rows: Iterable[Mapping[str, Any]], given: str) -> TraceChoice:
    """The trace of the results ``rows`` (with ``trace_id``, ``name``, ``source``) that ``given``
    names (see the module docstring); UserError (one line, naming ``--trace``) when it names none
    or several."""
    traces = list({row["trace_id"]: _Trace(row["trace_id"], row["name"], row["source"] or "") for row in rows}.values())
    found = _named(traces, given)
    if found:
        return TraceChoice(_only(found, given))
    window = _WINDOW.fullmatch(given)
    if window is not None and (found := _named(traces, window["name"])):
        return TraceChoice(_only(found, given), (int(window["start"]), int(window["end"])))
    raise UserError(f"--trace {given}: the results have no such trace; {_listing(traces, given)}")


def _named(traces: list[_Trace], given: str) -> list[_Trace]:
    """The traces ``given`` names exactly, else those whose source file it names."""
    return [t for t in traces if given in t.names()] or [t for t in traces if t.is_file(given)]


def _only(found: list[_Trace], given: str) -> str:
    if len(found) > 1:
        listed = ", ".join(t.described() for t in found[:LISTED])
        raise UserError(f"--trace {given}: {len(found)} traces have that name; give one's trace_id: {listed}")
    return found[0].trace_id


def _listing(traces: list[_Trace], given: str) -> str:
    if len(traces) <= LISTED:
        return "traces: " + ", ".join(f"{t.name} ({t.trace_id})" for t in traces)
    near = nearest(given, sorted({name for t in traces for name in (t.name, t.trace_id)}))
    if not near:
        return f"none of its {counted(len(traces), 'trace')} has a near name"
    return f"nearest of its {counted(len(traces), 'trace')}: {', '.join(near)}"


def _same_file(path: str, source: str) -> bool:
    try:
        return Path(path).resolve() == Path(source).resolve()
    except (OSError, ValueError):
        return False


def chosen_match(source: Any, trace: str | None, match: int | None) -> tuple[str, int | None]:
    """The trace and match number ``show`` draws from a :class:`~scenegrep.view.sources.ResultsSource`:
    without ``trace`` the ``match``-th match of the table (default 0); with it, the trace it names
    (:func:`choose_trace`) and its match number ``match`` (default 0; None for a trace without a
    match), or its match at the ``:START-END`` the name gave (``match``, if given, must be that one)."""
    if trace is None:
        row = source.match_row(match or 0)
        return row["trace_id"], row["match"]
    choice = choose_trace(source.results.table.select(["trace_id", "name", "source"]).to_pylist(), trace)
    matches = [r for r in source.rows_of(choice.trace_id) if r["status"] == "match"]
    if choice.window is None:
        return choice.trace_id, ((match or 0) if matches else None)
    at_window = [r["match"] for r in matches if (r["start_frame"], r["end_frame"]) == choice.window]
    first, last = choice.window
    if not at_window:
        raise UserError(f"--trace {trace}: the trace has no match at frames {first}-{last}")
    if match is not None and match not in at_window:
        raise UserError(f"--match {match}: the match at frames {first}-{last} is match {at_window[0]}")
    return choice.trace_id, at_window[0] if match is None else match
