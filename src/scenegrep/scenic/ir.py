"""The project's own intermediate representation of a Scenic program.

Scenic's parser produces Python ``ast`` nodes mixed with Scenic's node classes;
:mod:`.adapter` turns them into the small, typed tree defined here, so nothing
outside the adapter depends on Scenic's AST. Every node carries the :class:`Span`
of its source text for error messages. Scenic operators and specifiers keep
their Scenic names (``relative to``, ``ahead of``) as :class:`Operator` and
:class:`Specifier` nodes whose operand order is documented in :data:`OPERATORS`
and :data:`SPECIFIERS`; a missing optional operand is ``None``.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Span:
    """A stretch of the program text: 1-based line and column of its first and last character."""

    line: int
    column: int
    end_line: int
    end_column: int


NOWHERE = Span(1, 1, 1, 1)
"""The span of nodes the adapter synthesises (they never appear in error messages)."""


@dataclass(frozen=True)
class Node:
    """Base of all IR nodes; ``span`` is excluded from equality."""

    span: Span = field(default=NOWHERE, compare=False, kw_only=True)


# ---------------------------------------------------------------------------- expressions
@dataclass(frozen=True)
class Constant(Node):
    """A literal: number, string, boolean or None."""

    value: float | int | str | bool | None


@dataclass(frozen=True)
class Name(Node):
    """A variable or built-in name (``ego``, ``road``, ``Range``)."""

    id: str


@dataclass(frozen=True)
class Attribute(Node):
    """``value.attr`` (``ego.position``, ``globalParameters.weather``)."""

    value: Node
    attr: str


@dataclass(frozen=True)
class Sequence(Node):
    """A tuple or list literal ``(a, b)`` / ``[a, b]``; a 2-tuple is also a vector."""

    items: tuple[Node, ...]


@dataclass(frozen=True)
class Mapping(Node):
    """A dict literal ``{a: 1, b: 2}`` (the weights of ``Discrete``)."""

    keys: tuple[Node, ...]
    values: tuple[Node, ...]


@dataclass(frozen=True)
class Unary(Node):
    """``-x``, ``+x`` or ``not x``."""

    op: str
    operand: Node


@dataclass(frozen=True)
class Binary(Node):
    """Arithmetic ``left op right`` with op one of ``+ - * / // % **``."""

    op: str
    left: Node
    right: Node


@dataclass(frozen=True)
class Compare(Node):
    """One comparison ``left op right``, op one of ``< <= > >= == != in not in is is not``.

    Python's chains ``a < b < c`` become :class:`BoolOp` ``and`` of single comparisons.
    """

    op: str
    left: Node
    right: Node


@dataclass(frozen=True)
class BoolOp(Node):
    """``and`` / ``or`` of two or more operands."""

    op: str
    operands: tuple[Node, ...]


@dataclass(frozen=True)
class Temporal(Node):
    """A temporal operator of a requirement: ``always``, ``eventually``, ``next`` (one operand),
    ``until`` or ``implies`` (two: left, right)."""

    op: str
    operands: tuple[Node, ...]


@dataclass(frozen=True)
class Conditional(Node):
    """``body if test else orelse``."""

    test: Node
    body: Node
    orelse: Node


@dataclass(frozen=True)
class Call(Node):
    """A call of a named function (``Range(1, 2)``, ``abs(x)``, ``localPath('m.xodr')``)."""

    function: str
    args: tuple[Node, ...]
    keywords: tuple[tuple[str, Node], ...] = ()


OPERATORS = {
    "deg": "X deg",
    "vector": "X @ Y",
    "relative to": "X relative to Y",
    "offset along": "X offset along H by Y",
    "field at": "F at X",
    "relative position": "relative position of X [from Y]",
    "relative heading": "relative heading of X [from Y]",
    "apparent heading": "apparent heading of X [from Y]",
    "distance": "distance from X [to Y]",
    "distance past": "distance past X [of Y]",
    "angle": "angle [from X] [to Y]",
    "follow": "follow F from X for D",
    "visible": "visible R",
    "not visible": "not visible R",
    "visible from": "R visible from P",
    "not visible from": "R not visible from P",
    "can see": "X can see Y",
    "intersects": "X intersects Y",
    "front of": "front of O",
    "back of": "back of O",
    "left of": "left of O",
    "right of": "right of O",
    "front left of": "front left of O",
    "front right of": "front right of O",
    "back left of": "back left of O",
    "back right of": "back right of O",
}
"""Scenic operators of the IR: name -> syntax, operands in the order they appear there."""


@dataclass(frozen=True)
class Operator(Node):
    """A Scenic operator (see :data:`OPERATORS`); absent optional operands are ``None``."""

    name: str
    operands: tuple[Node | None, ...]


SPECIFIERS = {
    "with": "with P V (the property name is in Specifier.property)",
    "at": "at X",
    "in": "in R",
    "on": "on R",
    "contained in": "contained in R",
    "offset by": "offset by V",
    "offset along": "offset along H by V",
    "left of": "left of X [by D]",
    "right of": "right of X [by D]",
    "ahead of": "ahead of X [by D]",
    "behind": "behind X [by D]",
    "beyond": "beyond X by D [from Z]",
    "visible": "visible [from B]",
    "not visible": "not visible [from B]",
    "following": "following F [from X] for D",
    "facing": "facing H",
    "facing toward": "facing toward X",
    "facing away from": "facing away from X",
    "apparently facing": "apparently facing H [from X]",
}
"""Scenic specifiers of the IR: name -> syntax, operands in the order they appear there."""


@dataclass(frozen=True)
class Specifier(Node):
    """One specifier of a ``new`` (see :data:`SPECIFIERS`)."""

    name: str
    operands: tuple[Node | None, ...]
    property: str | None = None


@dataclass(frozen=True)
class New(Node):
    """``new Class spec, spec, ...``: an object (or Point/OrientedPoint) of a Scenic class."""

    class_name: str
    specifiers: tuple[Specifier, ...]


# ---------------------------------------------------------------------------- statements
@dataclass(frozen=True)
class Param(Node):
    """``param name = value`` (one per parameter of a ``param`` line)."""

    name: str
    value: Node


@dataclass(frozen=True)
class Model(Node):
    """``model dotted.name``: the world model the program uses."""

    name: str


@dataclass(frozen=True)
class Assign(Node):
    """``name = value``; ``ego = value`` sets the ego object."""

    name: str
    value: Node


@dataclass(frozen=True)
class Evaluate(Node):
    """An expression statement, e.g. an unnamed ``new Car``."""

    value: Node


@dataclass(frozen=True)
class Require(Node):
    """``require cond``, or ``require[p] cond`` (soft, p < 1), with an optional name."""

    condition: Node
    probability: float | None = None
    name: str | None = None


@dataclass(frozen=True)
class Repeat(Node):
    """``for variable in range(count): body`` with ``count`` a constant expression."""

    variable: str
    count: Node
    body: tuple[Node, ...]


# ---------------------------------------------------------------------------- behaviours
@dataclass(frozen=True)
class Do(Node):
    """``do B(args)``: run behaviour call ``behaviour`` (a :class:`Call`) to its end."""

    behaviour: Call


@dataclass(frozen=True)
class DoUntil(Node):
    """``do B(args) until condition``: run ``behaviour`` until ``condition`` holds (checked before each step)."""

    behaviour: Call
    condition: Node


@dataclass(frozen=True)
class DoFor(Node):
    """``do B(args) for amount seconds|steps``: run ``behaviour`` for at most that long."""

    behaviour: Call
    amount: Node
    unit: str


@dataclass(frozen=True)
class Interrupt(Node):
    """``interrupt when condition:`` and its handler ``body``."""

    condition: Node
    body: tuple[Node, ...]


@dataclass(frozen=True)
class TryInterrupt(Node):
    """``try: body`` with its ``interrupt when`` handlers in the order written (Scenic runs the last one
    written first when several conditions hold)."""

    body: tuple[Node, ...]
    handlers: tuple[Interrupt, ...]


@dataclass(frozen=True)
class Take(Node):
    """``take actions`` or ``wait``: one step of actions (their values are not modelled)."""


@dataclass(frozen=True)
class Forever(Node):
    """``while True: body``."""

    body: tuple[Node, ...]


@dataclass(frozen=True)
class BehaviourDef(Node):
    """``behavior name(params): body``; ``defaults`` aligns with ``params`` (None: no default)."""

    name: str
    params: tuple[str, ...]
    defaults: tuple[Node | None, ...]
    body: tuple[Node, ...]


@dataclass(frozen=True)
class Program(Node):
    """A whole program: its statements, text and file name."""

    statements: tuple[Node, ...]
    text: str = field(default="", compare=False)
    filename: str = field(default="<program>", compare=False)
