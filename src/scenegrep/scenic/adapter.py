"""Scenic's AST -> the project's IR (:mod:`.ir`): the one module that knows Scenic's node classes.

Scenic 3.1.1's parser returns a Python ``ast.Module`` whose nodes are Python's
(``Assign``, ``Call``, ``Compare`` ...) and Scenic's (``New``, ``RelativeToOp``,
``DirectionOfSpecifier`` ...). Nodes are dispatched on their class *name*, so the
adapter works whichever copy of Scenic's node classes produced them (see
:mod:`.parser`). Everything outside the supported fragment (imports, function or
class definitions, monitors, loops other than ``for i in range(n)``, method
calls, subscripts) is rejected with its line and column, never skipped.
Behaviour bodies keep seed 000's fragment: ``do``, ``do ... until``,
``do ... for``, sequences, ``try``/``interrupt when``, and ``while True:`` loops
of ``take``/``wait`` (a user-defined primitive behaviour).
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from typing import Any

from ..errors import UserError
from . import ir
from .errors import program_error
from .parser import parse_scenic

_BINARY = {"Add": "+", "Sub": "-", "Mult": "*", "Div": "/", "FloorDiv": "//", "Mod": "%", "Pow": "**"}
_UNARY = {"USub": "-", "UAdd": "+", "Not": "not"}
_COMPARE = {
    "Lt": "<",
    "LtE": "<=",
    "Gt": ">",
    "GtE": ">=",
    "Eq": "==",
    "NotEq": "!=",
    "In": "in",
    "NotIn": "not in",
    "Is": "is",
    "IsNot": "is not",
}
_DIRECTIONS = {"LeftOf": "left of", "RightOf": "right of", "AheadOf": "ahead of", "Behind": "behind"}
_POSITIONS = {
    "Front": "front of",
    "Back": "back of",
    "Left": "left of",
    "Right": "right of",
    "FrontLeft": "front left of",
    "FrontRight": "front right of",
    "BackLeft": "back left of",
    "BackRight": "back right of",
}
_SPECIFIER_FIELDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "AtSpecifier": ("at", ("position",)),
    "InSpecifier": ("in", ("region",)),
    "OnSpecifier": ("on", ("region",)),
    "ContainedInSpecifier": ("contained in", ("region",)),
    "OffsetBySpecifier": ("offset by", ("offset",)),
    "OffsetAlongSpecifier": ("offset along", ("direction", "offset")),
    "BeyondSpecifier": ("beyond", ("position", "offset", "base")),
    "VisibleSpecifier": ("visible", ("base",)),
    "NotVisibleSpecifier": ("not visible", ("base",)),
    "FollowingSpecifier": ("following", ("field", "base", "distance")),
    "FacingSpecifier": ("facing", ("heading",)),
    "FacingTowardSpecifier": ("facing toward", ("position",)),
    "FacingDirectlyTowardSpecifier": ("facing toward", ("position",)),
    "FacingAwayFromSpecifier": ("facing away from", ("position",)),
    "FacingDirectlyAwayFromSpecifier": ("facing away from", ("position",)),
    "ApparentlyFacingSpecifier": ("apparently facing", ("heading", "base")),
}
_OPERATOR_FIELDS: dict[str, tuple[str, tuple[str, ...]]] = {
    "DegOp": ("deg", ("operand",)),
    "VectorOp": ("vector", ("left", "right")),
    "FieldAtOp": ("field at", ("left", "right")),
    "RelativeToOp": ("relative to", ("left", "right")),
    "OffsetAlongOp": ("offset along", ("base", "direction", "offset")),
    "RelativePositionOp": ("relative position", ("target", "base")),
    "RelativeHeadingOp": ("relative heading", ("target", "base")),
    "ApparentHeadingOp": ("apparent heading", ("target", "base")),
    "DistanceFromOp": ("distance", ("target", "base")),
    "DistancePastOp": ("distance past", ("target", "base")),
    "AngleFromOp": ("angle", ("base", "target")),
    "FollowOp": ("follow", ("target", "base", "distance")),
    "VisibleOp": ("visible", ("region",)),
    "NotVisibleOp": ("not visible", ("region",)),
    "VisibleFromOp": ("visible from", ("region", "base")),
    "NotVisibleFromOp": ("not visible from", ("region", "base")),
    "CanSeeOp": ("can see", ("left", "right")),
    "IntersectsOp": ("intersects", ("left", "right")),
}
_UNSUPPORTED_STATEMENTS = {
    "Import": "imports are not supported: a query cannot run other libraries",
    "ImportFrom": "imports are not supported: a query cannot run other libraries",
    "FunctionDef": "function definitions are not supported",
    "AsyncFunctionDef": "function definitions are not supported",
    "ClassDef": "class definitions are not supported",
    "MonitorDef": "monitors are not supported",
    "ScenarioDef": "modular scenarios are not supported",
    "If": "if statements are not supported",
    "While": "while loops are not supported",
    "With": "with statements are not supported",
    "Try": "try statements are not supported",
}


class Adapter:
    """Converts one parsed program; errors point into its text."""

    def __init__(self, text: str, filename: str):
        self.program = ir.Program((), text=text, filename=filename)

    # ---------------------------------------------------------------- helpers
    def span(self, node: ast.AST) -> ir.Span:
        """The node's place; Scenic leaves some nodes (``override``) unplaced: then their first placed part's."""
        node = next((n for n in ast.walk(node) if getattr(n, "lineno", None) is not None), node)
        line = getattr(node, "lineno", 1)
        column = getattr(node, "col_offset", 0) + 1
        end_line = getattr(node, "end_lineno", None) or line
        end_column = (getattr(node, "end_col_offset", None) or column) + 1
        return ir.Span(line, column, end_line, end_column)

    def error(self, message: str, node: ast.AST) -> UserError:
        return program_error(message, self.span(node), self.program)

    # ---------------------------------------------------------------- statements
    def statements(self, body: list[ast.AST]) -> tuple[ir.Node, ...]:
        out: list[ir.Node] = []
        for node in body:
            out.extend(self.statement(node))
        return tuple(out)

    def statement(self, node: ast.AST) -> list[ir.Node]:
        kind = type(node).__name__
        if kind in _UNSUPPORTED_STATEMENTS:
            raise self.error(_UNSUPPORTED_STATEMENTS[kind], node)
        handler: Callable[[Any], list[ir.Node]] | None = getattr(self, f"stmt_{kind}", None)
        if handler is None:
            raise self.error(f"{_describe(node)} is not supported in a query", node)
        return handler(node)

    def stmt_Param(self, node: Any) -> list[ir.Node]:
        return [ir.Param(p.identifier, self.expr(p.value), span=self.span(p)) for p in node.elts]

    def stmt_Model(self, node: Any) -> list[ir.Node]:
        return [ir.Model(node.name, span=self.span(node))]

    def stmt_Assign(self, node: Any) -> list[ir.Node]:
        if len(node.targets) != 1 or type(node.targets[0]).__name__ != "Name":
            raise self.error("only assignments to one plain name are supported", node)
        return [ir.Assign(node.targets[0].id, self.expr(node.value), span=self.span(node))]

    def stmt_TrackedAssign(self, node: Any) -> list[ir.Node]:
        if type(node.target).__name__ != "Ego":
            raise self.error(f"assigning {type(node.target).__name__.lower()} is not supported", node)
        return [ir.Assign("ego", self.expr(node.value), span=self.span(node))]

    def stmt_Expr(self, node: Any) -> list[ir.Node]:
        if type(node.value).__name__ == "Constant" and isinstance(node.value.value, str):
            return []  # a docstring
        return [ir.Evaluate(self.expr(node.value), span=self.span(node))]

    def stmt_Pass(self, node: Any) -> list[ir.Node]:
        return []

    def stmt_Require(self, node: Any) -> list[ir.Node]:
        probability = None if node.prob is None else float(node.prob)
        return [ir.Require(self.expr(node.cond), probability, node.name, span=self.span(node))]

    def stmt_For(self, node: Any) -> list[ir.Node]:
        iterator = node.iter
        is_range = (
            type(iterator).__name__ == "Call"
            and type(iterator.func).__name__ == "Name"
            and iterator.func.id == "range"
            and len(iterator.args) == 1
            and not iterator.keywords
        )
        if type(node.target).__name__ != "Name" or not is_range or node.orelse:
            raise self.error("only loops of the form 'for name in range(count):' are supported", node)
        body = self.statements(node.body)
        return [ir.Repeat(node.target.id, self.expr(iterator.args[0]), body, span=self.span(node))]

    def stmt_BehaviorDef(self, node: Any) -> list[ir.Node]:
        args = node.args
        if args.posonlyargs or args.kwonlyargs or args.vararg or args.kwarg:
            raise self.error("behaviour parameters must be plain names (no *args, **kwargs or keyword-only)", node)
        if node.header:
            raise self.error("behaviour preconditions and invariants are not supported", node.header[0])
        params = tuple(a.arg for a in args.args)
        padding: list[ir.Node | None] = [None] * (len(params) - len(args.defaults))
        defaults = tuple(padding + [self.expr(d) for d in args.defaults])
        body = self.behaviour_body(node.body, node)
        return [ir.BehaviourDef(node.name, params, defaults, body, span=self.span(node))]

    # ---------------------------------------------------------------- behaviour bodies
    def behaviour_body(self, body: list[ast.AST], owner: ast.AST) -> tuple[ir.Node, ...]:
        out = [s for s in (self.behaviour_statement(node) for node in body) if s is not None]
        if not out:
            raise self.error("a behaviour block must do something (do, take or wait)", owner)
        return tuple(out)

    def behaviour_statement(self, node: Any) -> ir.Node | None:
        kind = type(node).__name__
        span = self.span(node)
        if kind == "Expr" and type(node.value).__name__ == "Constant" and isinstance(node.value.value, str):
            return None
        if kind == "Pass":
            return None
        if kind in ("Take", "Wait"):
            return ir.Take(span=span)
        if kind == "Do":
            return ir.Do(self.behaviour_call(node), span=span)
        if kind == "DoUntil":
            return ir.DoUntil(self.behaviour_call(node), self.expr(node.cond), span=span)
        if kind == "DoFor":
            unit = "steps" if type(node.duration).__name__ == "Steps" else "seconds"
            return ir.DoFor(self.behaviour_call(node), self.expr(node.duration.value), unit, span=span)
        if kind == "TryInterrupt":
            return self.try_interrupt(node)
        if kind == "While" and type(node.test).__name__ == "Constant" and node.test.value is True and not node.orelse:
            return ir.Forever(self.behaviour_body(node.body, node), span=span)
        raise self.error(f"{_describe(node)} is not supported in a behaviour (seed 000's fragment)", node)

    def behaviour_call(self, node: Any) -> ir.Call:
        if len(node.elts) != 1:
            raise self.error("running several behaviours at once ('do A, B') is not supported", node)
        call = self.expr(node.elts[0])
        if not isinstance(call, ir.Call):
            raise self.error("'do' needs a behaviour call such as FollowLaneBehavior()", node.elts[0])
        return call

    def try_interrupt(self, node: Any) -> ir.Node:
        if node.except_handlers or node.orelse or node.finalbody:
            raise self.error("'except', 'else' and 'finally' are not supported with 'try'", node)
        handlers = tuple(
            ir.Interrupt(self.expr(h.cond), self.behaviour_body(h.body, h), span=self.span(h))
            for h in node.interrupt_when_handlers
        )
        return ir.TryInterrupt(self.behaviour_body(node.body, node), handlers, span=self.span(node))

    # ---------------------------------------------------------------- expressions
    def expr(self, node: ast.AST) -> ir.Node:
        kind = type(node).__name__
        if kind in _OPERATOR_FIELDS:
            name, fields = _OPERATOR_FIELDS[kind]
            return ir.Operator(name, self.operands(node, fields), span=self.span(node))
        handler: Callable[[Any], ir.Node] | None = getattr(self, f"expr_{kind}", None)
        if handler is None:
            raise self.error(f"{_describe(node)} is not supported in a query", node)
        return handler(node)

    def operands(self, node: ast.AST, fields: tuple[str, ...]) -> tuple[ir.Node | None, ...]:
        return tuple(None if getattr(node, f, None) is None else self.expr(getattr(node, f)) for f in fields)

    def expr_Constant(self, node: Any) -> ir.Node:
        if not isinstance(node.value, (int, float, str, bool, type(None))) or isinstance(node.value, complex):
            raise self.error(f"the literal {node.value!r} is not supported", node)
        return ir.Constant(node.value, span=self.span(node))

    def expr_Name(self, node: Any) -> ir.Node:
        return ir.Name(node.id, span=self.span(node))

    def expr_Attribute(self, node: Any) -> ir.Node:
        return ir.Attribute(self.expr(node.value), node.attr, span=self.span(node))

    def expr_Tuple(self, node: Any) -> ir.Node:
        return ir.Sequence(tuple(self.expr(e) for e in node.elts), span=self.span(node))

    expr_List = expr_Tuple

    def expr_Dict(self, node: Any) -> ir.Node:
        if any(k is None for k in node.keys):
            raise self.error("dictionary unpacking is not supported", node)
        keys = tuple(self.expr(k) for k in node.keys)
        return ir.Mapping(keys, tuple(self.expr(v) for v in node.values), span=self.span(node))

    def expr_UnaryOp(self, node: Any) -> ir.Node:
        op = _UNARY.get(type(node.op).__name__)
        if op is None:
            raise self.error("the operator ~ is not supported", node)
        return ir.Unary(op, self.expr(node.operand), span=self.span(node))

    def expr_BinOp(self, node: Any) -> ir.Node:
        op = _BINARY.get(type(node.op).__name__)
        if op is None:
            raise self.error(f"the operator {type(node.op).__name__} is not supported", node)
        return ir.Binary(op, self.expr(node.left), self.expr(node.right), span=self.span(node))

    def expr_Compare(self, node: Any) -> ir.Node:
        operands = [self.expr(node.left)] + [self.expr(c) for c in node.comparators]
        pairs = [
            ir.Compare(_COMPARE[type(op).__name__], left, right, span=self.span(node))
            for op, left, right in zip(node.ops, operands, operands[1:])
        ]
        return pairs[0] if len(pairs) == 1 else ir.BoolOp("and", tuple(pairs), span=self.span(node))

    def expr_BoolOp(self, node: Any) -> ir.Node:
        op = "and" if type(node.op).__name__ == "And" else "or"
        return ir.BoolOp(op, tuple(self.expr(v) for v in node.values), span=self.span(node))

    def expr_Always(self, node: Any) -> ir.Node:
        return ir.Temporal("always", (self.expr(node.value),), span=self.span(node))

    def expr_Eventually(self, node: Any) -> ir.Node:
        return ir.Temporal("eventually", (self.expr(node.value),), span=self.span(node))

    def expr_Next(self, node: Any) -> ir.Node:
        return ir.Temporal("next", (self.expr(node.value),), span=self.span(node))

    def expr_UntilOp(self, node: Any) -> ir.Node:
        return ir.Temporal("until", (self.expr(node.left), self.expr(node.right)), span=self.span(node))

    def expr_ImpliesOp(self, node: Any) -> ir.Node:
        return ir.Temporal("implies", (self.expr(node.hypothesis), self.expr(node.conclusion)), span=self.span(node))

    def expr_IfExp(self, node: Any) -> ir.Node:
        return ir.Conditional(self.expr(node.test), self.expr(node.body), self.expr(node.orelse), span=self.span(node))

    def expr_Call(self, node: Any) -> ir.Node:
        if type(node.func).__name__ != "Name":
            raise self.error("only calls of built-in functions by name are supported (no method calls)", node)
        if any(type(a).__name__ == "Starred" for a in node.args) or any(k.arg is None for k in node.keywords):
            raise self.error("argument unpacking is not supported", node)
        args = tuple(self.expr(a) for a in node.args)
        keywords = tuple((k.arg, self.expr(k.value)) for k in node.keywords)
        return ir.Call(node.func.id, args, keywords, span=self.span(node))

    def expr_New(self, node: Any) -> ir.Node:
        specifiers = tuple(self.specifier(s) for s in node.specifiers)
        return ir.New(node.className, specifiers, span=self.span(node))

    def expr_PositionOfOp(self, node: Any) -> ir.Node:
        name = _POSITIONS.get(type(node.position).__name__)
        if name is None:
            raise self.error("3-D position operators (top, bottom) are not supported in 2-D queries", node)
        return ir.Operator(name, (self.expr(node.target),), span=self.span(node))

    # ---------------------------------------------------------------- specifiers
    def specifier(self, node: Any) -> ir.Specifier:
        kind = type(node).__name__
        span = self.span(node)
        if kind == "WithSpecifier":
            return ir.Specifier("with", (self.expr(node.value),), property=node.prop, span=span)
        if kind == "DirectionOfSpecifier":
            name = _DIRECTIONS.get(type(node.direction).__name__)
            if name is None:
                raise self.error("'above' and 'below' are 3-D specifiers, not supported in 2-D queries", node)
            return ir.Specifier(name, self.operands(node, ("position", "distance")), span=span)
        if kind not in _SPECIFIER_FIELDS:
            raise self.error(f"the specifier {_describe(node)} is not supported", node)
        name, fields = _SPECIFIER_FIELDS[kind]
        return ir.Specifier(name, self.operands(node, fields), span=span)


def _describe(node: ast.AST) -> str:
    """A readable name for a node class: ``WhileLoop`` -> 'while loop'."""
    name = type(node).__name__
    words = "".join(" " + c.lower() if c.isupper() else c for c in name).strip()
    return f"'{words}'"


def adapt(tree: ast.Module, text: str, filename: str) -> ir.Program:
    """The IR of a parsed program."""
    adapter = Adapter(text, filename)
    return ir.Program(adapter.statements(tree.body), text=text, filename=filename)


def parse_program(text: str, filename: str = "<program>") -> ir.Program:
    """Parse Scenic source text into the IR; any error is a one-line :class:`UserError` with line:column."""
    return adapt(parse_scenic(text, filename), text, filename)
