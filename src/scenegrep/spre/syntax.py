"""The abstract syntax of Spatial Regular Expressions (seed 004, Defs. 1-4, plus scenegrep's
extensions), shared by both parsers.

Four layers: a *query* (regular expression over frames) whose letters are *spatial
formulas* (true or false of a frame), which compare *metric expressions* (real numbers)
and test *spatial terms* (sets of regions: boxes, their intersections, complements...).

Nodes are immutable values: their fields are their annotations, compared and hashed
structurally, except ``span`` (start, end offsets into the query text), so structurally
equal formulas are one letter of the alphabet. They share one :class:`Node` base rather
than being dataclasses, because generating methods for thirty classes would cost tens of
milliseconds at every start of the command line.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

Span = tuple[int, int]


class Node:
    """Base of syntax nodes: keyword or positional construction, immutability, structural
    equality and hashing that ignore ``span``, ``match`` support, a readable repr."""

    __slots__ = ()
    _fields: tuple[str, ...] = ()

    def __init_subclass__(cls) -> None:
        cls._fields = tuple(name for name in cls.__dict__.get("__annotations__", {}) if not name.startswith("_"))
        cls.__match_args__ = tuple(f for f in cls._fields if f != "span")

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        values = dict(zip(self._fields, args)) | kwargs
        for name in self._fields:
            value = values[name] if name in values else getattr(type(self), f"_default_{name}", _MISSING)
            if value is _MISSING:
                raise TypeError(f"{type(self).__name__} needs {name}")
            object.__setattr__(self, name, value)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable")

    def _key(self) -> tuple:
        return (type(self), *(getattr(self, f) for f in self.__match_args__))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Node) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(f'{f}={getattr(self, f)!r}' for f in self.__match_args__)})"

    def children(self) -> Iterator[Node]:
        """The nodes directly inside this one."""
        for name in self.__match_args__:
            value = getattr(self, name)
            for item in value if isinstance(value, tuple) else (value,):
                if isinstance(item, Node):
                    yield item

    def walk(self) -> Iterator[Node]:
        """This node and every node inside it, depth first (without recursion)."""
        stack: list[Node] = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(list(node.children())))


_MISSING = object()


# ---------------------------------------------------------------------- spatial terms
class Filter(Node):
    """An attribute filter inside a class atom, e.g. ``score>=0.5`` or ``colour=red``."""

    key: str
    op: str
    value: str | float


class ClassAtom(Node):
    """``[:name:]`` or ``[:name:filter,...:]``: the objects of a class (``*`` is any class).
    As a term, their regions; as a formula, "some such object is present"."""

    name: str
    filters: tuple[Filter, ...]
    _default_filters = ()
    span: Span
    _default_span = (0, 0)


class Var(Node):
    """A variable bound by a quantifier: as a term, the bound object's region."""

    name: str
    span: Span
    _default_span = (0, 0)


class Complement(Node):
    term: Term
    span: Span
    _default_span = (0, 0)


class Intersection(Node):
    left: Term
    right: Term
    span: Span
    _default_span = (0, 0)


class Union(Node):
    left: Term
    right: Term
    span: Span
    _default_span = (0, 0)


class Interior(Node):
    term: Term
    span: Span
    _default_span = (0, 0)


class Closure(Node):
    term: Term
    span: Span
    _default_span = (0, 0)


Term = ClassAtom | Var | Complement | Intersection | Union | Interior | Closure


# ---------------------------------------------------------------------- metric expressions
class Number(Node):
    value: float
    span: Span
    _default_span = (0, 0)


class Function(Node):
    """``@name(term, ...)`` (or the paper's ``<name>(...)``): a real-valued function of regions."""

    name: str
    args: tuple[Term, ...]
    span: Span
    _default_span = (0, 0)


class Negate(Node):
    operand: Metric
    span: Span
    _default_span = (0, 0)


class Arithmetic(Node):
    """``+ - * / ^`` over the cartesian product of the operands' values."""

    op: str
    left: Metric
    right: Metric
    span: Span
    _default_span = (0, 0)


Metric = Number | Function | Negate | Arithmetic


# ---------------------------------------------------------------------- spatial formulas
class Not(Node):
    operand: Formula
    span: Span
    _default_span = (0, 0)


class And(Node):
    left: Formula
    right: Formula
    span: Span
    _default_span = (0, 0)


class Or(Node):
    left: Formula
    right: Formula
    span: Span
    _default_span = (0, 0)


class Binding(Node):
    """``v := [:class:]`` in a quantifier."""

    var: str
    atom: ClassAtom
    span: Span
    _default_span = (0, 0)


class Quantifier(Node):
    """``E(v := [:c:], ...) body`` (some assignment satisfies the body) or ``A(...) body``
    (every assignment does, and there is at least one)."""

    kind: str
    bindings: tuple[Binding, ...]
    body: Formula
    span: Span
    _default_span = (0, 0)


class NonEmpty(Node):
    """``NE(term)`` / ``<nonempty>(term)``: some region of the term is non-empty."""

    term: Term
    span: Span
    _default_span = (0, 0)


class Subset(Node):
    """``t1 <subset> t2`` / ``t1 <= t2`` on terms: some non-empty region of t1 lies in a region of t2."""

    left: Term
    right: Term
    span: Span
    _default_span = (0, 0)


class Compare(Node):
    """``m1 op m2``, op one of ``< > <= >= == !=``: true for some pair of values."""

    op: str
    left: Metric
    right: Metric
    span: Span
    _default_span = (0, 0)


class Relation(Node):
    """``<frontof>(a, b)``, ``<behind>``, ``<leftof>``, ``<rightof>``, ``<above>``, ``<below>``:
    some region of a lies on that side of some region of b (of the ego when b is omitted)."""

    name: str
    left: Term
    right: Term | None
    span: Span
    _default_span = (0, 0)


class Present(Node):
    """A term used as a formula (a class atom or variable): it has some region."""

    term: Term
    span: Span
    _default_span = (0, 0)


Formula = Not | And | Or | Quantifier | NonEmpty | Subset | Compare | Relation | Present


# ---------------------------------------------------------------------- queries (regex layer)
class Letter(Node):
    """``[formula]``: one frame satisfying the formula."""

    formula: Formula
    span: Span
    _default_span = (0, 0)


class AnyFrame(Node):
    """``.``: any one frame."""

    span: Span
    _default_span = (0, 0)


class Concat(Node):
    items: tuple[Query, ...]
    span: Span
    _default_span = (0, 0)


class Alternation(Node):
    options: tuple[Query, ...]
    span: Span
    _default_span = (0, 0)


class Repeat(Node):
    """``Q{low,high}`` (``high`` None for unbounded); ``*`` is {0,}, ``+`` {1,}, ``?`` {0,1}."""

    item: Query
    low: int
    high: int | None
    span: Span
    _default_span = (0, 0)


class TrackBinder(Node):
    """``E(v := [:c:]) (Q)`` at the query level: one object (track) of class c, the same in
    every frame of the sub-query's match, is bound to ``v`` throughout Q."""

    binding: Binding
    body: Query
    span: Span
    _default_span = (0, 0)


class Empty(Node):
    """The empty query (matches only the empty sequence, so never reports a match)."""

    span: Span
    _default_span = (0, 0)


Query = Letter | AnyFrame | Concat | Alternation | Repeat | TrackBinder | Empty
