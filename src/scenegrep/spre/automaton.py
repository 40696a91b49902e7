"""From a query to an automaton over frames, and the one-pass matchers that run it.

Compilation is Glushkov's construction: every letter occurrence (after expanding
repetitions and instantiating track binders) is a *position*; a position is entered by
consuming one frame that satisfies its letter. ``first`` positions start a match,
``last`` ones end it, ``follow[p]`` lists the positions that may come after p.

Running is a lazily built DFA whose states are *ordered* tuples of positions, each slot
carrying a register (RE2 and Rust's regex-automata compile once and run in linear time;
this adds per-slot registers, after Laurikari's tagged automata). At every frame a new
thread starts; threads in the same position merge, keeping the register of the earlier
slot. Run forward with registers = start positions, slots stay ordered by start, so the
first accepting slot is the longest match ending at this frame (online matching). Run
backward over the reversed automaton with registers = end positions, slots are ordered
by end, latest first, so the first accepting slot is the longest match starting at this
frame; a greedy scan of those gives the leftmost-longest non-overlapping matches
(offline). Both passes are linear in the number of frames, with memory independent of
the match lengths; transitions are computed once per (state, frame symbol) and cached.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from . import syntax as s
from .tokens import MAX_POSITIONS

ANY = -1
"""The letter of ``.`` positions: satisfied by every frame."""

MAX_CACHED_STATES = 10_000
"""DFA states kept before the transition cache is cleared (as RE2 does when it fills)."""

MAX_EDGES = 4_000_000
"""Most follow-list entries an automaton may have (Glushkov automata can be quadratic in their
positions: ``([[:car:]]?){0,5000}``); about 32 MB."""


class TooLarge(Exception):
    """The automaton would have more than :data:`MAX_POSITIONS` positions (repetitions expanded,
    track binders instantiated per object) or :data:`MAX_EDGES` transitions."""


LetterKey = tuple[s.Formula, tuple[tuple[str, int], ...]]
"""A distinct letter: a formula and the track bindings it is evaluated under."""


@dataclass(frozen=True)
class Automaton:
    """Glushkov automaton: the letter of each position, first/last positions and follow lists."""

    letters: tuple[LetterKey, ...]
    position_letter: tuple[int, ...]
    first: tuple[int, ...]
    last: frozenset[int]
    follow: tuple[tuple[int, ...], ...]

    def reversed(self) -> Automaton:
        """The automaton of the reversed language (same positions and letters)."""
        back: list[list[int]] = [[] for _ in self.follow]
        for p, successors in enumerate(self.follow):
            for q in successors:
                back[q].append(p)
        return Automaton(
            self.letters,
            self.position_letter,
            tuple(sorted(self.last)),
            frozenset(self.first),
            tuple(tuple(b) for b in back),
        )


class _Builder:
    def __init__(self, candidates: dict[s.Binding, Sequence[int]]):
        self.candidates = candidates
        self.letters: dict[LetterKey, int] = {}
        self.position_letter: list[int] = []
        self.follow: list[list[int]] = []
        self.edges = 0

    def position(self, letter: int) -> int:
        if len(self.position_letter) >= MAX_POSITIONS:
            raise TooLarge(f"the query expands to more than {MAX_POSITIONS} frame letters")
        self.position_letter.append(letter)
        self.follow.append([])
        return len(self.position_letter) - 1

    def link(self, lasts: Sequence[int], firsts: Sequence[int]) -> None:
        self.edges += len(lasts) * len(firsts)
        if self.edges > MAX_EDGES:
            raise TooLarge(f"the query's automaton has more than {MAX_EDGES} transitions")
        for p in lasts:
            self.follow[p].extend(firsts)

    def build(self, node: s.Query, env: dict[str, int]) -> tuple[list[int], list[int], bool]:
        """(first positions, last positions, nullable) of a fresh copy of ``node``."""
        match node:
            case s.Letter(formula):
                key = (formula, tuple(sorted(env.items())))
                letter = self.letters.setdefault(key, len(self.letters))
                p = self.position(letter)
                return [p], [p], False
            case s.AnyFrame():
                p = self.position(ANY)
                return [p], [p], False
            case s.Empty():
                return [], [], True
            case s.Concat(items):
                return self.concat([lambda item=item: self.build(item, env) for item in items])
            case s.Alternation(options):
                return self.alternation([self.build(option, env) for option in options])
            case s.Repeat(item, low, high):
                return self.repeat(lambda: self.build(item, env), low, high)
            case s.TrackBinder(binding, body):
                copies = [self.build(body, {**env, binding.var: obj}) for obj in self.candidates[binding]]
                return self.alternation(copies)
        raise TypeError(f"not a query node: {node!r}")

    def concat(self, parts: list) -> tuple[list[int], list[int], bool]:
        first, last, nullable = [], [], True
        for part in parts:
            p_first, p_last, p_nullable = part()
            self.link(last, p_first)
            first = first + p_first if nullable else first
            last = last + p_last if p_nullable else p_last
            nullable = nullable and p_nullable
        return first, last, nullable

    @staticmethod
    def alternation(copies: list[tuple[list[int], list[int], bool]]) -> tuple[list[int], list[int], bool]:
        first = [p for c in copies for p in c[0]]
        last = [p for c in copies for p in c[1]]
        return first, last, any(c[2] for c in copies) or not copies

    def star(self, copy: tuple[list[int], list[int], bool]) -> tuple[list[int], list[int], bool]:
        first, last, _ = copy
        self.link(last, first)
        return first, last, True

    def repeat(self, fresh, low: int, high: int | None) -> tuple[list[int], list[int], bool]:
        parts = [fresh for _ in range(low)]
        if high is None:
            parts.append(lambda: self.star(fresh()))
        elif high > low:
            parts.append(lambda: self.optional_chain(fresh, high - low))
        return self.concat(parts) if parts else ([], [], True)

    def optional_chain(self, fresh, count: int) -> tuple[list[int], list[int], bool]:
        """``(X (X (...)?)?)?`` with ``count`` copies of X, built from the innermost copy out
        (no recursion, so ``{0,500}`` is as cheap as ``{500}``)."""
        copies = [fresh() for _ in range(count)]
        first: list[int] = []
        for c_first, c_last, c_nullable in reversed(copies):
            self.link(c_last, first)
            first = c_first + first if c_nullable else c_first
        return first, [p for _, c_last, _ in copies for p in c_last], True


def compile_automaton(query: s.Query, candidates: dict[s.Binding, Sequence[int]] | None = None) -> Automaton:
    """The Glushkov automaton of a query; ``candidates`` lists the objects each track binder ranges over."""
    builder = _Builder(candidates or {})
    first, last, _ = builder.build(query, {})
    follow = tuple(tuple(dict.fromkeys(f)) for f in builder.follow)
    return Automaton(
        tuple(builder.letters), tuple(builder.position_letter), tuple(dict.fromkeys(first)), frozenset(last), follow
    )


class Runner:
    """The lazily built ordered-subset DFA of an automaton (see the module docstring)."""

    def __init__(self, automaton: Automaton):
        self.automaton = automaton
        self._reset()

    def _reset(self) -> None:
        self.states: list[tuple[int, ...]] = [()]
        self.ids: dict[tuple[int, ...], int] = {(): 0}
        self.table: list[dict[int, tuple[int, tuple[int, ...], int]]] = [{}]

    def _holds(self, position: int, mask: int) -> bool:
        letter = self.automaton.position_letter[position]
        return letter == ANY or (mask >> letter) & 1 == 1

    def transition(self, state: int, mask: int) -> tuple[int, tuple[int, ...], int]:
        """(next state, where each next slot's register comes from: an old slot or -1 for the
        thread starting now, first accepting slot or -1) on a frame with letter mask ``mask``.

        When the cache is full it is cleared; ``state`` is then stale, but the returned state
        is valid, and callers only ever use the returned one."""
        found = self.table[state].get(mask)
        if found is not None:
            return found
        a = self.automaton
        positions: list[int] = []
        origin: list[int] = []
        seen: set[int] = set()
        for slot, p in enumerate(self.states[state]):
            for q in a.follow[p]:
                if q not in seen and self._holds(q, mask):
                    seen.add(q)
                    positions.append(q)
                    origin.append(slot)
        for q in a.first:
            if q not in seen and self._holds(q, mask):
                seen.add(q)
                positions.append(q)
                origin.append(-1)
        target = tuple(positions)
        cacheable = True
        if target not in self.ids:
            if len(self.states) >= MAX_CACHED_STATES:
                self._reset()
                cacheable = False
            self.ids[target] = len(self.states)
            self.states.append(target)
            self.table.append({})
        accept = next((k for k, q in enumerate(positions) if q in a.last), -1)
        result = (self.ids[target], tuple(origin), accept)
        if cacheable:
            self.table[state][mask] = result
        return result


class ForwardScan:
    """The online matcher: feed frames in order, in chunks of any size; each frame may report
    the longest match ending there. Memory is independent of the stream length."""

    def __init__(self, automaton: Automaton):
        self.runner = Runner(automaton)
        self.state = 0
        self.registers: list[object] = []

    def feed(self, masks: Sequence[int], frames: Sequence[object]) -> list[tuple[object, int]]:
        """Consume frames (letter masks, and what to remember of each as a start); returns
        (start of the longest match ending at frame k, k) for each frame k of the chunk that ends one."""
        runner = self.runner
        table = runner.table
        state, registers = self.state, self.registers
        found_matches = []
        for k, mask in enumerate(masks):
            found = table[state].get(mask)
            state, origin, accept = found if found is not None else runner.transition(state, mask)
            table = runner.table
            registers = [registers[i] if i >= 0 else frames[k] for i in origin]
            if accept >= 0:
                found_matches.append((registers[accept], k))
        self.state, self.registers = state, registers
        return found_matches


def longest_from_each_start(automaton: Automaton, masks: Sequence[int]) -> np.ndarray:
    """For every frame position i, the end (exclusive) of the longest match starting at i, or -1."""
    runner = Runner(automaton.reversed())
    ends = [-1] * len(masks)
    table, transition = runner.table, runner.transition
    state, registers = 0, []
    for i in range(len(masks) - 1, -1, -1):
        found = table[state].get(masks[i])
        state, origin, accept = found if found is not None else transition(state, masks[i])
        table = runner.table
        registers = [registers[k] if k >= 0 else i + 1 for k in origin]
        if accept >= 0:
            ends[i] = registers[accept]
    return np.array(ends, dtype=np.int64)


def leftmost_longest(ends: np.ndarray) -> Iterator[tuple[int, int]]:
    """Non-overlapping leftmost-longest matches (start, end) from the longest end per start:
    take the first start with a match, jump to its end, repeat (one step per match)."""
    n = len(ends)
    candidate = np.where(ends > 0, np.arange(n), n)
    next_start = np.append(np.minimum.accumulate(candidate[::-1])[::-1], n).tolist()
    end_of = ends.tolist()
    position = next_start[0]
    while position < n:
        end = end_of[position]
        yield position, end
        position = next_start[end]
