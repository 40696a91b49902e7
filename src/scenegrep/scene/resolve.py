"""Resolution: a Scenic program's IR -> a :class:`~.program.SceneProgram` of feature terms.

Statements run in order, as Scenic runs them: ``param`` and ``model`` lines,
assignments, ``new`` objects (built by :mod:`.specifiers`), ``require`` and
``for i in range(n)`` loops (unrolled). Expressions evaluate to values of
:mod:`.values` by :mod:`.expressions`. Every error names the line and column of
the offending text.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..errors import UserError
from ..scenic import ir
from ..scenic.errors import program_error
from . import expressions
from .domain import MODELS, Default
from .program import TRACE, Requirement, SceneProgram
from .regions import WALKABLE, Everywhere, MapField, MapRegion, Nowhere, Union
from .specifiers import add_collision_requirements, construct
from .terms import Term
from .values import Instance, Namespace

MAX_LOOP_STATEMENTS = 1_000
"""Most statements all the program's ``for`` loops may run together (each may create an object)."""

SIMULATOR_PARAMS = frozenset(
    {"map", "map_options", "carla_map", "lgsvl_map", "render", "timestep", "time_step", "use2DMap"}
)
"""Parameters that configure Scenic or a simulator rather than describe the scene."""

NETWORK = {
    "drivableRegion": MapRegion("drivable"),
    "roadRegion": MapRegion("road"),
    "laneRegion": MapRegion("lane"),
    "intersectionRegion": MapRegion("intersection"),
    "crossingRegion": MapRegion("crossing"),
    "sidewalkRegion": MapRegion("sidewalk"),
    "walkableRegion": WALKABLE,
    "curbRegion": MapRegion("curb"),
    "shoulderRegion": MapRegion("shoulder"),
    "roadDirection": MapField("lanes"),
}
"""Attributes of the driving domain's ``network`` the map can give."""

DRIVING_NAMES = {
    "road": MapRegion("drivable"),
    "intersection": MapRegion("intersection"),
    "crossing": MapRegion("crossing"),
    "sidewalk": MapRegion("sidewalk"),
    "curb": MapRegion("curb"),
    "shoulder": MapRegion("shoulder"),
    "roadOrShoulder": Union((MapRegion("drivable"), MapRegion("shoulder"))),
    "roadDirection": MapField("lanes"),
    "roadRegion": MapRegion("drivable"),
    "workspace": Everywhere(),
    "everywhere": Everywhere(),
    "nowhere": Nowhere(),
}
"""Global names of the driving domain (``scenic/domains/driving/model.scenic``) and Scenic's
``everywhere`` / ``nowhere``; ``crossing`` and ``roadRegion`` are extensions, named as in Scenic's
webots and GTA world models."""


class Resolver:
    """Resolves one program; see the module docstring. Use :func:`resolve`. It is the
    :class:`~.context.Context` that :mod:`.expressions` and :mod:`.specifiers` evaluate in."""

    def __init__(
        self, program: ir.Program, visible_distance: float | None = None, free_fields: frozenset[str] = frozenset()
    ):
        self.program = program
        self.visible_distance = visible_distance
        self.free_fields = free_fields
        """Names of map fields (:class:`.regions.MapField`) whose values are free headings: a
        region oriented by one gives objects an unconstrained parent orientation."""
        self.scene = SceneProgram(program)
        self.f = self.scene.factory
        self.scope: dict[str, Any] = {}
        self.params: dict[str, Any] = {}
        self.instances: list[Instance] = []
        self.suffix = ""
        self.loop_statements = 0
        self.self_view: Any = None
        self.behaviours: dict[str, ir.BehaviourDef] = {}
        """The program's behaviour definitions by name (they do not shape the scene; see :mod:`scenegrep.scenario`)."""
        self.temporal: list[tuple[ir.Require, dict[str, Any]]] = []
        """Requirements with temporal operators and the scope they were stated in (they do not shape
        the initial scene; :mod:`scenegrep.scenario.temporal` monitors them over the window)."""

    def error(self, message: str, where: ir.Node | ir.Span) -> UserError:
        return program_error(message, where, self.program)

    # ---------------------------------------------------------------- statements
    def run(self) -> SceneProgram:
        for statement in self.program.statements:
            self.statement(statement)
        if "ego" not in self.scope:
            raise self.error("the program defines no ego object ('ego = new Car ...')", ir.NOWHERE)
        add_collision_requirements(self)
        return self.scene

    def statement(self, node: ir.Node) -> None:
        if isinstance(node, ir.Param):
            self.param(node)
        elif isinstance(node, ir.Model):
            if node.name not in MODELS:
                raise self.error(f"unknown world model {node.name!r}; supported: {', '.join(MODELS)}", node)
        elif isinstance(node, ir.Assign):
            self.assign(node)
        elif isinstance(node, ir.Evaluate):
            self.evaluate(node.value, name=None)
        elif isinstance(node, ir.Require):
            self.require(node)
        elif isinstance(node, ir.Repeat):
            self.repeat(node)
        elif isinstance(node, ir.BehaviourDef):
            self.behaviours[node.name] = node
        else:
            raise self.error(f"{type(node).__name__} statements are not supported", node)

    def param(self, node: ir.Param) -> None:
        self.check_map_setting(node)
        value = self.evaluate(node.value, name=None)
        if node.name == "map":
            if not (isinstance(value, Term) and value.kind == "str"):
                raise self.error("param map must be a file name", node.value)
            self.scene.map_path = value.value
        self.params[node.name] = value
        if isinstance(value, Term) and value.kind in ("num", "str", "bool") and node.name not in SIMULATOR_PARAMS:
            self.scene.params[node.name] = value
            observed = self.f.observed(TRACE, node.name, value.kind)
            equal = self.f.op("eq", value, observed, kind="bool")
            text = f"param {node.name} equals the trace's attribute {node.name}"
            self.scene.requirements.append(Requirement(equal, text, node.span, parameter=node.name))

    def check_map_setting(self, node: ir.Param) -> None:
        """Scenic's map settings queries cannot honour are errors: ``map_options`` (Scenic's map
        loader's options; maps are read with its defaults) unless empty, ``use2DMap`` unless True
        (Scenic refuses 3-D maps)."""
        empty = isinstance(node.value, ir.Mapping) and not node.value.keys
        if node.name == "map_options" and not empty:
            raise self.error("param map_options is not supported: maps are read with Scenic's default options", node)
        if node.name == "use2DMap" and node.value != ir.Constant(True):
            raise self.error("param use2DMap must be True: queries are 2-D (Scenic supports no 3-D maps)", node)

    def assign(self, node: ir.Assign) -> None:
        if node.name in DRIVING_NAMES or node.name in ("network", "globalParameters", "self"):
            raise self.error(f"cannot assign to the built-in name {node.name!r}", node)
        value = self.evaluate(node.value, name=node.name)
        if node.name == "ego" and not (isinstance(value, Instance) and value.is_object):
            raise self.error("ego must be an object ('ego = new Car ...')", node.value)
        if node.name == "ego" and "ego" in self.scope:
            raise self.error("ego is assigned twice", node)
        self.scope[node.name] = value

    def require(self, node: ir.Require) -> None:
        if is_temporal(node.condition):
            if node.probability is not None:
                raise self.error("a soft requirement (require[p]) cannot use temporal operators", node)
            self.temporal.append((node, dict(self.scope)))
            return
        condition = expressions.to_bool(self, self.evaluate(node.condition, name=None), node.condition)
        if node.probability is not None and not 0 <= node.probability <= 1:
            raise self.error("a require probability must lie in [0, 1]", node)
        text = source_text(self.program, node.condition.span)
        self.scene.requirements.append(Requirement(condition, f"require {text}", node.span, node.probability))

    def repeat(self, node: ir.Repeat) -> None:
        count = self.evaluate(node.count, name=None)
        if not (isinstance(count, Term) and count.is_const and count.kind == "num" and float(count.value).is_integer()):
            raise self.error("a loop count must be a constant whole number", node.count)
        self.loop_statements += max(0, int(count.value)) * max(1, len(node.body))
        if self.loop_statements > MAX_LOOP_STATEMENTS:
            raise self.error(f"loops may run at most {MAX_LOOP_STATEMENTS} statements in all", node.count)
        outer = self.suffix
        for i in range(int(count.value)):
            self.scope[node.variable] = self.f.const(i)
            self.suffix = f"{outer}#{i}"
            for statement in node.body:
                self.statement(statement)
        self.suffix = outer

    # ---------------------------------------------------------------- expressions
    def evaluate(self, node: ir.Node, name: str | None) -> Any:
        """The value of an expression; ``name`` names an object created by a top-level ``new``."""
        if isinstance(node, ir.New):
            return construct(self, node, self.instance_name(node, name))
        return expressions.evaluate(self, node)

    def evaluate_default(self, default: Default) -> Any:
        """A class default's value; its messages and labels point into the default's own text."""
        outer, self.program = self.program, default.program
        try:
            return self.evaluate(default.expression, name=None)
        finally:
            self.program = outer

    def instance_name(self, node: ir.New, name: str | None) -> str:
        base = f"{name}{self.suffix}" if name else f"{node.class_name}@{node.span.line}{self.suffix}"
        taken = {i.name for i in self.instances}
        return base if base not in taken else f"{base}@{node.span.line}"

    def lookup(self, node: ir.Name) -> Any:
        """The value of a name: program variable, ``self``, driving-domain name or namespace."""
        if node.id in self.scope:
            return self.scope[node.id]
        if node.id == "self":
            if self.self_view is None:
                raise self.error("'self' is only defined inside an object's specifiers", node)
            return self.self_view
        if node.id == "ego":
            raise self.error("ego is used before it is defined", node)
        if node.id in DRIVING_NAMES:
            return DRIVING_NAMES[node.id]
        if node.id == "network":
            return Namespace("network", NETWORK)
        if node.id == "globalParameters":
            return Namespace("globalParameters", self.params)
        if node.id in ("pi", "tau"):
            return self.f.const(math.pi if node.id == "pi" else math.tau)
        raise self.error(f"unknown name {node.id!r}", node)

    def label(self, node: ir.Node) -> str:
        """How a random value is named in explanations: its source text and place, ``Range(4, 10)@2:36``."""
        text = source_text(self.program, node.span)
        text = text if len(text) <= 40 else text[:37] + "..."
        if self.program.filename.startswith("<default "):
            return f"{text} ({self.program.filename[1:-1]}){self.suffix}"
        return f"{text}@{node.span.line}:{node.span.column}{self.suffix}"

    def local_path(self, relative: str) -> str:
        """``localPath``: a path relative to the program's folder."""
        folder = Path(self.program.filename).parent
        return str((folder / relative).resolve())


def source_text(program: ir.Program, span: ir.Span) -> str:
    """The program text of a one-line span, or its first line."""
    lines = program.text.splitlines()
    if not 0 < span.line <= len(lines):
        return "..."
    line = lines[span.line - 1]
    end = span.end_column if span.end_line == span.line else len(line) + 1
    return line[span.column - 1 : end - 1].strip()


def resolve(program: ir.Program) -> SceneProgram:
    """The scene program of an IR program (see the module docstring)."""
    return Resolver(program).run()


def is_temporal(node: ir.Node) -> bool:
    """Whether a requirement's condition is temporal: a temporal operator, possibly under
    ``and``, ``or`` and ``not`` (Scenic's propositions; anywhere else one is an error)."""
    if isinstance(node, ir.Temporal):
        return True
    if isinstance(node, ir.BoolOp):
        return any(is_temporal(o) for o in node.operands)
    return isinstance(node, ir.Unary) and node.op == "not" and is_temporal(node.operand)
