"""Running a compiled SpRE over label traces: offline (all matches) and online (per frame).

Pipeline per trace: build the space (image channels or top-down boxes), compile the
query to an automaton (track binders range over the trace's objects of their class),
evaluate each distinct letter once over all frames into a truth matrix, turn each
frame's true letters into a bit mask, and run one linear pass
(:mod:`scenegrep.spre.automaton`).

Offline: all non-overlapping, non-empty, leftmost-longest matches. Online: after every
frame, the longest non-empty match ending there.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..errors import UserError
from ..model import LabelTrace
from . import syntax as s
from .automaton import (
    Automaton,
    ForwardScan,
    TooLarge,
    compile_automaton,
    leftmost_longest,
    longest_from_each_start,
)
from .checks import check, check_strem_online
from .errors import query_error
from .evaluate import Evaluator, TooManyRows
from .parser import parse
from .space import Space, image_space, topdown_space
from .strem_parser import parse_strem
from .tokens import MAX_CHARACTERS
from .vocabulary import SeenNames


@dataclass(frozen=True)
class CompiledQuery:
    """A parsed and checked query, with the warnings parsing produced and, for a query without
    track binders, its automaton (which then depends on no trace, so it is built, and its size
    checked, once before any trace is read)."""

    text: str
    tree: s.Query
    compat: bool = False
    warnings: tuple[str, ...] = ()
    automaton: Automaton | None = None

    @property
    def has_track_binders(self) -> bool:
        return any(isinstance(node, s.TrackBinder) for node in self.tree.walk())

    def automaton_over(self, candidates: dict[s.Binding, list[int]]) -> Automaton:
        """The automaton with track binders over ``candidates`` (the one built at compile time
        when there are none)."""
        return self.automaton if self.automaton is not None and not candidates else automaton_of(self, candidates)


def compile_query(text: str, compat: bool = False, source: str = "<query>") -> CompiledQuery:
    """Parse and check a query (scenegrep's syntax, or STREM's with ``compat``); UserError on any problem."""
    if len(text) > MAX_CHARACTERS:
        raise query_error(
            f"the query is longer than {MAX_CHARACTERS} characters", text, MAX_CHARACTERS, len(text), source
        )
    if compat:
        tree, warnings = parse_strem(text, source)
    else:
        tree, warnings = parse(text, source), []
    checked = check(tree, text, source, compat)
    query = CompiledQuery(text, tree, compat, tuple(warnings) + checked.warnings)
    return query if query.has_track_binders else replace(query, automaton=automaton_of(query))


def automaton_of(query: CompiledQuery, candidates: dict[s.Binding, list[int]] | None = None) -> Automaton:
    """The query's automaton (track binders over ``candidates``); a :class:`UserError` at the query
    when it is over the automaton's size limits."""
    try:
        return compile_automaton(query.tree, candidates)
    except TooLarge as exc:
        raise query_error(f"{exc}; use smaller repetitions", query.text, 0, max(len(query.text), 1)) from None


@dataclass(frozen=True)
class SearchOptions:
    """Where to search: ``space`` image or topdown (None: image when the trace has image
    detections, else topdown), the image ``channels`` to keep (None: all), and how many
    leading frames to ``skip``."""

    space: str | None = None
    channels: tuple[str, ...] | None = None
    skip: int = 0


class Match(NamedTuple):
    """A match: frames at positions [start, end) of the searched stream, the dataset frame
    index and time (s) of its first and last frame, and the object ids bound by track
    binders (variable -> id; None when the query has none)."""

    start: int
    end: int
    first_index: int
    last_index: int
    start_time: float
    end_time: float
    bound: dict[str, str] | None = None

    @property
    def index_range(self) -> tuple[int, int]:
        """STREM's printed range: first frame's index .. last frame's index + 1."""
        return self.first_index, self.last_index + 1


def build_space(trace: LabelTrace, options: SearchOptions, compat: bool) -> Space:
    """The space a query runs in over this trace."""
    kind = options.space or ("image" if trace.images is not None else "topdown")
    if kind == "image":
        return image_space(trace, options.channels, match_kinds=not compat)
    if compat:
        raise UserError("--compat strem searches image detections only; STREM has no top-down space")
    return topdown_space(trace, match_kinds=True)


def _candidates(query: CompiledQuery, evaluator: Evaluator) -> dict[s.Binding, list[int]]:
    out = {}
    for node in query.tree.walk():
        if isinstance(node, s.TrackBinder):
            rows, _ = evaluator.class_rows(node.binding.atom)
            objects = np.unique(evaluator.space.object[rows])
            if len(rows) and (objects < 0).all():
                raise UserError("a track binder E(...)(...) needs object identities, and this stream has none")
            out[node.binding] = objects[objects >= 0].tolist()
    return out


def letter_masks(automaton: Automaton, evaluator: Evaluator, query: CompiledQuery, trace: LabelTrace) -> list[int]:
    """Per frame, the bit mask of the automaton's letters that hold in it; a :class:`UserError`
    at the quantifier, naming the dataset frame index, when nested quantifiers make too many
    rows in a frame of ``trace`` (the evaluator's trace)."""
    n = evaluator.space.n_frames
    truth = np.zeros((len(automaton.letters), n), dtype=bool)
    for k, (formula, bindings) in enumerate(automaton.letters):
        try:
            truth[k] = evaluator.frames(formula, dict(bindings))
        except TooManyRows as exc:
            frame = int(trace.frame_index[exc.frame])
            raise query_error(f"{exc} (frame {frame})", query.text, *exc.quantifier.span) from None
    if len(automaton.letters) <= 62:
        weights = np.left_shift(np.int64(1), np.arange(len(automaton.letters), dtype=np.int64))
        return (truth.T.astype(np.int64) * weights).sum(axis=1).tolist()
    packed = np.packbits(truth.T, axis=1, bitorder="little")
    return [int.from_bytes(row.tobytes(), "little") for row in packed]


class TraceSearch:
    """A query bound to one trace: its automaton and per-frame letter masks."""

    def __init__(self, query: CompiledQuery, trace: LabelTrace, options: SearchOptions = SearchOptions()):
        if options.skip:
            trace = trace.slice_frames(options.skip, trace.n_frames)
        self.query = query
        self.trace = trace
        self.options = options
        self.evaluator = Evaluator(build_space(trace, options, query.compat), strem=query.compat)
        self.candidates = _candidates(query, self.evaluator)
        self.automaton = query.automaton_over(self.candidates)
        self.masks = letter_masks(self.automaton, self.evaluator, query, trace)

    @property
    def warnings(self) -> list[str]:
        """One line per class name of the query and image channel of the options that this trace
        lacks (:mod:`scenegrep.spre.vocabulary`; classes of all its channels): names that can never
        hold here."""
        seen = SeenNames()
        seen.add(self.trace, self.evaluator.space.kind)
        return seen.warnings(self.query.tree, self.query.compat, self.options.channels)

    def matches(self, spans: Iterable[tuple[int, int]]) -> Iterator[Match]:
        """Matches of the given (start, end) position pairs."""
        idx, times = self.trace.frame_index.tolist(), self.trace.frame_time.tolist()
        for start, end in spans:
            bound = self._bound(start, end) if self.candidates else None
            yield Match(start, end, idx[start], idx[end - 1], times[start], times[end - 1], bound)

    def _bound(self, start: int, end: int) -> dict[str, str]:
        """For each track binder, the object whose instantiation alone matches exactly [start, end)."""
        bound = {}
        for binding, objects in self.candidates.items():
            for obj in objects:
                only = {**self.candidates, binding: [obj]}
                automaton = automaton_of(self.query, only)
                masks = letter_masks(automaton, self.evaluator, self.query, self.trace)[start:end]
                ends = longest_from_each_start(automaton, masks)
                if len(ends) and ends[0] == end - start:
                    bound[binding.var] = str(self.evaluator.space.object_ids[obj])
                    break
        return bound

    def offline(self) -> Iterator[Match]:
        """The non-overlapping leftmost-longest matches, in order."""
        ends = longest_from_each_start(self.automaton, self.masks)
        yield from self.matches(leftmost_longest(ends))

    def online(self) -> Iterator[Match]:
        """After each frame, the longest match ending there (frames in order)."""
        if self.query.compat:
            check_strem_online(self.query.tree, self.query.text)
        found = ForwardScan(self.automaton).feed(self.masks, range(len(self.masks)))
        yield from self.matches((start, end + 1) for start, end in found)  # type: ignore[misc]


def search(
    query: CompiledQuery, trace: LabelTrace, options: SearchOptions = SearchOptions(), online: bool = False
) -> Iterator[Match]:
    """The matches of a query in a trace (offline, or online semantics over the whole trace)."""
    bound = TraceSearch(query, trace, options)
    return bound.online() if online else bound.offline()


def search_stream(
    query: CompiledQuery,
    chunks: Iterable[LabelTrace],
    options: SearchOptions = SearchOptions(),
    seen: SeenNames | None = None,
) -> Iterator[Match]:
    """Online matching over a stream that arrives as consecutive traces (e.g. STREM documents on
    stdin): each frame is matched as soon as its chunk arrives, in memory independent of the
    stream's length. Track binders need whole traces and are rejected here. ``seen`` (if given)
    gathers the names of the frames searched (skipped frames not), for the warnings of the names
    the query uses that the stream lacks (:meth:`SeenNames.warnings`, once the stream ended)."""
    if query.has_track_binders:
        raise UserError("track binders E(...)(...) need the whole trace; they cannot run on a live stream")
    if query.compat:
        check_strem_online(query.tree, query.text)
    automaton = query.automaton_over({})
    scan = ForwardScan(automaton)
    skip = options.skip
    position = 0
    for chunk in chunks:
        if skip:
            dropped = min(skip, chunk.n_frames)
            skip -= dropped
            chunk = chunk.slice_frames(dropped, chunk.n_frames)
        space = build_space(chunk, options, query.compat)
        if seen is not None and chunk.n_frames:
            seen.add(chunk, space.kind)
        evaluator = Evaluator(space, strem=query.compat)
        frames = list(
            zip(range(position, position + chunk.n_frames), chunk.frame_index.tolist(), chunk.frame_time.tolist())
        )
        for (first, first_index, first_time), k in scan.feed(letter_masks(automaton, evaluator, query, chunk), frames):
            _, last_index, last_time = frames[k]
            yield Match(first, position + k + 1, first_index, last_index, first_time, last_time)
        position += chunk.n_frames
