"""Semantic checks of a parsed query, before any data is read: known functions with the
right number of arguments, variables used only where a quantifier binds them, repetitions
of a sensible size, and (``--compat strem``) only what STREM v0.2.0 can run.

Every problem is a :class:`UserError` at the offending node, with a caret.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from ..errors import UserError
from . import syntax as s
from .errors import query_error
from .tokens import MAX_NESTING, MAX_NODES, MAX_POSITIONS, TOO_DEEP
from ..wording import plural

FUNCTIONS: dict[str, tuple[int, ...]] = {
    "x": (1,),
    "y": (1,),
    "z": (1,),
    "area": (1,),
    "width": (1,),
    "height": (1,),
    "w": (1,),
    "h": (1,),
    "dist": (1, 2),
    "gap": (2,),
    "iou": (2,),
    "score": (1,),
    "speed": (1,),
}
"""Metric functions and their allowed numbers of arguments (``w``/``h`` alias ``width``/``height``)."""

STREM_FUNCTIONS: dict[str, tuple[int, ...]] = {"x": (1,), "y": (1,), "area": (1,), "dist": (1, 2)}
"""The functions STREM v0.2.0 evaluates (any other name or arity makes it panic)."""

STREM_MAX_LETTERS = 52


@dataclass(frozen=True)
class Checked:
    """A query that passed the checks, and the warnings to show (compat mode's unbound variables)."""

    query: s.Query
    warnings: tuple[str, ...]


class _Checker:
    def __init__(self, text: str, source: str, compat: bool):
        self.text, self.source, self.compat = text, source, compat
        self.warnings: list[str] = []

    def fail(self, message: str, node: object) -> UserError:
        start, end = getattr(node, "span", (0, 0))
        return query_error(message, self.text, start, max(end, start + 1), self.source)

    def walk(self, node: s.Node, scope: frozenset[str]) -> None:
        if isinstance(node, s.Quantifier):
            for binding in node.bindings:
                self.walk(binding.atom, scope)
            self.walk(node.body, scope | {b.var for b in node.bindings})
            return
        if isinstance(node, s.TrackBinder):
            self.walk(node.binding.atom, scope)
            self.walk(node.body, scope | {node.binding.var})
            return
        self.check_node(node, scope)
        for child in node.children():
            self.walk(child, scope)

    def check_node(self, node: object, scope: frozenset[str]) -> None:
        if isinstance(node, s.Var) and node.name not in scope:
            if not self.compat:
                raise self.fail(f"variable {node.name!r} is not bound by an enclosing E(...) or A(...)", node)
            self.warnings.append(f"variable {node.name!r} is unbound and evaluates to no region (as in STREM)")
        elif isinstance(node, s.Function):
            self.check_function(node)
        elif isinstance(node, s.Complement) and self.compat:
            raise self.fail("STREM v0.2.0 cannot evaluate a term complement '!' (it panics); drop --compat strem", node)

    def check_function(self, node: s.Function) -> None:
        table = STREM_FUNCTIONS if self.compat else FUNCTIONS
        if node.name not in table:
            known = ", ".join(f"@{name}" for name in table)
            raise self.fail(f"unknown function @{node.name}; known: {known}", node)
        if len(node.args) not in table[node.name]:
            counts = " or ".join(str(n) for n in table[node.name])
            arguments = plural("argument", max(table[node.name]))
            raise self.fail(f"@{node.name} takes {counts} {arguments}, not {len(node.args)}", node)


_QUERY_NODES = (s.Letter, s.AnyFrame, s.Concat, s.Alternation, s.Repeat, s.TrackBinder, s.Empty)


def _sub_queries(query: s.Query) -> Iterator[s.Query]:
    return (c for c in query.children() if isinstance(c, _QUERY_NODES))  # type: ignore[misc]


def _letters(query: s.Query) -> int:
    """Letter occurrences of the query after expanding repetitions (the automaton's size)."""
    if isinstance(query, (s.Letter, s.AnyFrame)):
        return 1
    if isinstance(query, s.Repeat):
        return _letters(query.item) * max(query.low, query.high or 1, 1)
    return sum(_letters(c) for c in _sub_queries(query))


def _written_letters(query: s.Query) -> int:
    """``[...]`` occurrences as written (STREM's symbol count)."""
    if isinstance(query, s.Letter):
        return 1
    return sum(_written_letters(c) for c in _sub_queries(query))


def _too_big(query: s.Query) -> tuple[s.Node, str] | None:
    """The first node nested more than :data:`MAX_NESTING` levels below the root (chains of
    ``+ - * /`` nest one level per operator), or the node past :data:`MAX_NODES`, with the
    message; found without recursion."""
    stack: list[tuple[s.Node, int]] = [(query, 1)]
    seen = 0
    while stack:
        node, depth = stack.pop()
        seen += 1
        if depth > MAX_NESTING:
            return node, TOO_DEEP
        if seen > MAX_NODES:
            return node, f"the query has more than {MAX_NODES} terms and operators"
        stack.extend((child, depth + 1) for child in node.children())
    return None


def check(query: s.Query, text: str, source: str = "<query>", compat: bool = False) -> Checked:
    """Check a parsed query; returns it with any warnings, or raises a :class:`UserError`."""
    checker = _Checker(text, source, compat)
    too_big = _too_big(query)
    if too_big is not None:
        raise checker.fail(too_big[1], too_big[0])
    checker.walk(query, frozenset())
    if _letters(query) > MAX_POSITIONS:
        raise query_error(
            f"the query expands to more than {MAX_POSITIONS} frame letters; use smaller repetitions",
            text,
            0,
            max(len(text), 1),
            source,
        )
    if compat and _written_letters(query) > STREM_MAX_LETTERS:
        raise query_error(
            f"STREM v0.2.0 supports at most {STREM_MAX_LETTERS} [...] formulas per query",
            text,
            0,
            max(len(text), 1),
            source,
        )
    return Checked(query, tuple(checker.warnings))


def horizon(query: s.Query) -> float:
    """The longest match a query can have, in frames (seed 004, Def. 9; inf when unbounded)."""
    if isinstance(query, (s.Letter, s.AnyFrame)):
        return 1
    if isinstance(query, s.Empty):
        return 0
    if isinstance(query, s.Concat):
        return sum(horizon(item) for item in query.items)
    if isinstance(query, s.Alternation):
        return max(horizon(option) for option in query.options)
    if isinstance(query, s.Repeat):
        return float("inf") if query.high is None else query.high * horizon(query.item)
    if isinstance(query, s.TrackBinder):
        return horizon(query.body)
    raise TypeError(f"not a query node: {query!r}")


def check_strem_online(query: s.Query, text: str, source: str = "<query>") -> None:
    """STREM's online matcher keeps a window of the query's horizon and panics when it is 0
    (``Q{0}``); reproduce that as a clear error."""
    if not isinstance(query, s.Empty) and horizon(query) == 0:
        raise query_error(
            "STREM v0.2.0 cannot match a query whose longest match is 0 frames online (it panics); drop --compat strem",
            text,
            0,
            max(len(text), 1),
            source,
        )
