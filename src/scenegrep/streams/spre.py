"""SpRE over streams, as STREM searches them: each input read and searched in turn, or a live input.

Three ways a stream is searched (``scenegrep spre``'s stream modes: ``--compat strem``, ``--online``,
``--export``, standard input):

- :func:`input_searches`: each trace of an input file, read whole, searched offline (every
  leftmost-longest match) or online (after each frame, the longest match ending there), with the
  warnings for the names the query uses that the trace lacks (:class:`scenegrep.spre.SeenNames`);
- :class:`LiveSearch`: a live input (:mod:`.live`) searched online chunk by chunk; its warnings are
  known only once the stream has ended, since a class may appear at any later frame;
- :class:`MatchFormat`: how each match is written: the match's place ``SOURCE#NAME:START-END``
  (``SOURCE:START-END`` for a live stream, which has no trace name), STREM's ``PREFIX:START..END``
  (first index .. last index + 1), a JSON Lines record, or the matched frames as one-line JSON.

``source`` is the input's path as given, ``-`` for standard input; a warning names ``<stdin>`` for it.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from ..json_lines import line
from ..model import LabelTrace
from ..spre import CompiledQuery, Match, SearchOptions, SeenNames, TraceSearch, search_stream
from .live import LiveInput


def where(source: str) -> str:
    """How a warning names an input: its path, ``<stdin>`` for ``-``."""
    return "<stdin>" if source == "-" else source


@dataclass
class InputSearch:
    """One trace of an input searched: the input's ``source``, the ``prefix`` STREM prints before a
    match (``PATH``, ``PATH#NAME`` for a file of several traces, ``""`` for standard input), the bound
    ``search`` and its ``matches`` (an iterator: the search runs as they are asked for)."""

    source: str
    prefix: str
    search: TraceSearch
    matches: Iterator[Match]

    @property
    def trace(self) -> LabelTrace:
        """The trace searched (after ``skip``)."""
        return self.search.trace

    @property
    def warnings(self) -> list[str]:
        """``SOURCE: warning`` for each name the query uses that the trace lacks."""
        return [f"{where(self.source)}: {warning}" for warning in self.search.warnings]


def input_searches(query: CompiledQuery, source: str, options: SearchOptions, online: bool) -> Iterator[InputSearch]:
    """The traces of the input at ``source`` (``-``: standard input, STREM JSON), each searched as it
    is read: offline, or ``online``. UserError for an input that cannot be read, when it is read."""
    from .. import readers

    many = source != "-" and readers.FORMATS[readers.detect_format(source)].many
    for trace in readers.read_traces(source):
        search = TraceSearch(query, trace, options)
        prefix = "" if source == "-" else f"{source}#{trace.name}" if many else source
        yield InputSearch(source, prefix, search, search.online() if online else search.offline())


class LiveSearch:
    """A query searched online over a live input, chunk by chunk: :attr:`matches`, an iterator of
    the matches in order, each handed out as the frame that completes it is searched (counted and
    timed by the input's latency meter); :attr:`prefix`, STREM's (the path followed, ``""`` for
    standard input)."""

    def __init__(self, query: CompiledQuery, live: LiveInput, options: SearchOptions):
        self.query = query
        self.live = live
        self.options = options
        self.seen = SeenNames()
        self.prefix = "" if live.source == "-" else live.source
        self.matches = live.latency.each_match(search_stream(query, live.chunks, options, self.seen))

    @property
    def warnings(self) -> list[str]:
        """``SOURCE: warning`` for each name the query uses that no frame searched so far had (none
        before a frame was searched): complete once the stream has ended."""
        if not self.seen.frames:
            return []
        found = self.seen.warnings(self.query.tree, self.query.compat, self.options.channels)
        return [f"{where(self.live.source)}: {warning}" for warning in found]


@dataclass(frozen=True)
class MatchFormat:
    """How a stream search writes a match: a JSON Lines record (``json``), the matched frames
    (``export``), STREM's ``PREFIX:START..END`` (``strem``), else its place; ``options`` the search's
    (the channels an exported STREM document keeps, the space)."""

    json: bool = False
    export: bool = False
    strem: bool = False
    options: SearchOptions = SearchOptions()

    def text(self, match: Match, source: str, prefix: str = "", trace: LabelTrace | None = None) -> str:
        """One match of ``source``'s ``trace`` (None: a live stream, which has no trace name) as one
        line, without its newline; ``prefix`` is STREM's (see :class:`InputSearch`). A live match
        has no frames to export: it is written as its place."""
        if self.json:
            return line(match_record(match, source, trace))
        if self.export and trace is not None:
            return json.dumps(export_document(match, trace, self.options), separators=(",", ":"), allow_nan=True)
        if self.strem:
            span = "{}..{}".format(*match.index_range)
            return f"{prefix}:{span}" if prefix else span
        from ..dataset.places import place

        if trace is None:
            return f"{source}:{match.first_index}-{match.last_index}"
        return place(source, trace.name, match.first_index, match.last_index)


def match_record(match: Match, source: str, trace: LabelTrace | None = None) -> dict[str, Any]:
    """A match as a JSON Lines record: ``source`` (the path as given, ``-`` for standard input),
    ``start_frame``/``end_frame`` (dataset frame indices of its first and last frame),
    ``start_time``/``end_time`` (s), ``trace`` (its name; not for a live stream) and ``bound``
    (track variable -> object id; only when the query binds tracks)."""
    record: dict[str, Any] = {
        "source": source,
        "start_frame": match.first_index,
        "end_frame": match.last_index,
        "start_time": match.start_time,
        "end_time": match.end_time,
    }
    if trace is not None:
        record["trace"] = trace.name
    if match.bound:
        record["bound"] = match.bound
    return record


def export_document(match: Match, trace: LabelTrace, options: SearchOptions) -> dict[str, Any]:
    """The matched frames of ``trace``: a STREM JSON document of its image detections (the
    ``options``' channels) unless the search was top-down, else a scenegrep JSON trace document."""
    if trace.images is not None and options.space != "topdown":
        from ..writers.strem_json import strem_document

        return strem_document(trace, match.start, match.end, options.channels)
    from ..writers.trace_json import trace_document

    return trace_document(trace.slice_frames(match.start, match.end))
