"""Terms: the scalar expression DAG a Scenic program's scene compiles to.

Everything the decision procedure reasons about is a :class:`Term` over real
numbers, booleans and strings: vectors are pairs of terms, headings are terms
in radians (compared modulo 2π), and the geometric predicates that involve the
road map (a point in a region, a box inside a region, the road direction at a
point) are terms whose ``value`` names the region or field. The leaves are
constants, *observed* label values (the features of a program object, after
conditioning), continuous random variables (``Range`` ...), finite choices
(``Options`` ...) and the coordinates of random points in regions.

Terms are hash-consed by a :class:`TermFactory`: structurally equal terms are
the same object, so memoising on identity shares work, and constant operands
are folded as terms are built.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from ..scenic.ir import NOWHERE, Span

ARITHMETIC = ("add", "sub", "mul", "div", "neg", "pow", "abs", "min", "max", "sin", "cos", "sqrt", "heading_of", "wrap")
"""Real-valued operations. ``heading_of(dx, dy)`` is the Scenic heading of a direction
(``atan2(-dx, dy)``); ``wrap(a)`` normalises an angle into (-π, π]; ``pow`` has its integer
exponent as ``value``."""

COMPARISONS = ("lt", "le", "eq", "ne")
LOGIC = ("and", "or", "not", "ite")
GEOMETRY = ("in_region", "region_distance", "field", "box_in_region", "boxes_overlap", "box_visible", "follow")
"""Map and shape predicates; their ``value`` is a region, a field, or (``follow``) a field
and a coordinate index. See :mod:`.geometry` for their exact meaning."""

LEAVES = ("const", "observed", "var", "choice", "point")


@dataclass(frozen=True, eq=False)
class RandomVariable:
    """A continuous random variable of the program: values in [low, high] (terms; ±inf allowed)."""

    name: str
    low: Term
    high: Term
    span: Span = NOWHERE


@dataclass(frozen=True, eq=False)
class FiniteChoice:
    """A discrete random variable: the index of one of ``size`` alternatives."""

    name: str
    size: int
    span: Span = NOWHERE


@dataclass(frozen=True, eq=False)
class RandomPoint:
    """A point drawn uniformly from a region (``new Point in R``, ``on R``, ``visible`` ...)."""

    name: str
    region: Any
    span: Span = NOWHERE


class Term:
    """One node of the DAG: ``op``, ``args`` (terms) and an op-specific ``value``; see the module docstring."""

    __slots__ = ("op", "args", "value", "kind", "_leaves")

    def __init__(self, op: str, args: tuple[Term, ...], value: Any, kind: str):
        self.op = op
        self.args = args
        self.value = value
        self.kind = kind
        self._leaves: frozenset[Term] | None = None

    def __repr__(self) -> str:
        if self.op == "const":
            return repr(self.value)
        if self.op == "observed":
            return f"{self.value[0]}.{self.value[1]}"
        if self.op in ("var", "choice"):
            return self.value.name
        if self.op == "point":
            return f"{self.value[0].name}.{'xy'[self.value[1]]}"
        inner = ", ".join(repr(a) for a in self.args)
        return f"{self.op}({inner})"

    @property
    def is_const(self) -> bool:
        return self.op == "const"

    def leaves(self) -> frozenset[Term]:
        """The leaf terms below this one (constants excluded), including those inside regions and fields."""
        if self._leaves is None:
            found: set[Term] = set()
            for child in self.children():
                if child.op in LEAVES:
                    if child.op != "const":
                        found.add(child)
                    found.update(leaf_dependencies(child))
                else:
                    found.update(child.leaves())
            self._leaves = frozenset(found)
        return self._leaves

    def children(self) -> Iterator[Term]:
        """Argument terms, then the terms held by this node's region or field value."""
        yield from self.args
        yield from value_terms(self.value)


def value_terms(value: Any) -> Iterator[Term]:
    """Terms held inside a node's value (a region or field with term parameters), if any."""
    terms = getattr(value, "terms", None)
    if callable(terms):
        yield from terms()
    elif isinstance(value, tuple):
        for item in value:
            yield from value_terms(item)


def leaf_dependencies(leaf: Term) -> set[Term]:
    """Leaves a leaf itself depends on: the bounds of a random variable, the region of a random point
    (empty for other terms)."""
    if leaf.op == "var":
        return set(leaf.value.low.leaves() | leaf.value.high.leaves()) | {
            t for t in (leaf.value.low, leaf.value.high) if t.op in LEAVES and t.op != "const"
        }
    if leaf.op == "point":
        found: set[Term] = set()
        for term in value_terms(leaf.value[0].region):
            if term.op in LEAVES and term.op != "const":
                found.add(term)
            found.update(term.leaves())
        return found
    return set()


SCALAR_FUNCTIONS: dict[str, Callable[..., Any]] = {
    "add": lambda a, b: a + b,
    "sub": lambda a, b: a - b,
    "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b,
    "sqrt": math.sqrt,
    "neg": lambda a: -a,
    "abs": abs,
    "min": min,
    "max": max,
    "sin": math.sin,
    "cos": math.cos,
    "heading_of": lambda dx, dy: math.atan2(-dx, dy),
    "wrap": lambda a: math.pi - (math.pi - a) % (2 * math.pi),
    "lt": lambda a, b: a < b,
    "le": lambda a, b: a <= b,
    "eq": lambda a, b: a == b,
    "ne": lambda a, b: a != b,
    "not": lambda a: not a,
    "and": lambda a, b: bool(a and b),
    "or": lambda a, b: bool(a or b),
    "ite": lambda test, a, b: a if test else b,
}
"""Each operation on plain Python values, for folding constants and evaluating at a point."""


class TermFactory:
    """Builds hash-consed terms, folding operations on constants."""

    def __init__(self) -> None:
        self._table: dict[tuple[Any, ...], Term] = {}

    def _make(self, op: str, args: tuple[Term, ...], value: Any, kind: str) -> Term:
        key = (op, tuple(id(a) for a in args), value, kind)
        term = self._table.get(key)
        if term is None:
            term = Term(op, args, value, kind)
            self._table[key] = term
        return term

    # ---------------------------------------------------------------- leaves
    def const(self, value: Any) -> Term:
        """A constant: float for numbers, bool, str or None."""
        if isinstance(value, bool) or value is None or isinstance(value, str):
            return self._make("const", (), value, _kind_of(value))
        return self._make("const", (), float(value), "num")

    def observed(self, obj: str, feature: str, kind: str = "num") -> Term:
        """The labeled value of feature ``feature`` of the object matched to program object ``obj``."""
        return self._make("observed", (), (obj, feature), kind)

    def var(self, variable: RandomVariable) -> Term:
        return self._make("var", (), variable, "num")

    def choice(self, choice: FiniteChoice) -> Term:
        return self._make("choice", (), choice, "num")

    def point(self, point: RandomPoint) -> tuple[Term, Term]:
        """The x and y coordinate terms of a random point."""
        return self._make("point", (), (point, 0), "num"), self._make("point", (), (point, 1), "num")

    # ---------------------------------------------------------------- operations
    def op(self, op: str, *args: Term, value: Any = None, kind: str = "num") -> Term:
        """An operation, folded when every operand is constant and the op is a pure function."""
        if args and all(a.is_const for a in args) and (op in SCALAR_FUNCTIONS and value is None or op == "pow"):
            try:
                values = [a.value for a in args]
                return self.const(values[0] ** value if op == "pow" else SCALAR_FUNCTIONS[op](*values))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                pass
        simpler = _identity(op, args)
        if simpler is not None:
            return simpler
        return self._make(op, args, value, kind)

    def select(self, choice: Term, alternatives: tuple[Term, ...]) -> Term:
        """Alternative ``i`` where ``i`` is the value of the finite choice ``choice``."""
        if all(a is alternatives[0] for a in alternatives):
            return alternatives[0]
        return self._make("select", (choice, *alternatives), None, alternatives[0].kind)


def _is(term: Term, number: float) -> bool:
    return term.op == "const" and term.kind == "num" and term.value == number


def _identity(op: str, args: tuple[Term, ...]) -> Term | None:
    """The operand an operation with an identity element reduces to (x + 0, x * 1, 0 * x ...), or None."""
    if op == "add":
        return args[1] if _is(args[0], 0) else args[0] if _is(args[1], 0) else None
    if op == "sub" and _is(args[1], 0):
        return args[0]
    if op == "mul":
        if _is(args[0], 0) or _is(args[1], 0):
            return args[0] if _is(args[0], 0) else args[1]
        return args[1] if _is(args[0], 1) else args[0] if _is(args[1], 1) else None
    if op == "div" and _is(args[1], 1):
        return args[0]
    if op == "neg" and args[0].op == "neg":
        return args[0].args[0]
    if op in ("and", "or"):
        absorbing = op == "or"
        for a, b in (args, args[::-1]):
            if a.op == "const" and a.kind == "bool":
                return a if a.value is absorbing else b
    return None


def _kind_of(value: Any) -> str:
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, str):
        return "str"
    return "none" if value is None else "num"
