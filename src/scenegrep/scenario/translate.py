"""Syntax-directed translation of a program's behaviours to HFSMs (seed 000 §4.3, Fig. 2).

Each program object's ``with behavior B(args)`` becomes an :class:`~.hfsm.Hfsm`:
a behaviour the program defines becomes the states of its body (statements in
sequence, ``do``/``until``/``for``, ``try``/``interrupt when``); a behaviour whose
body is ``while True:`` of ``take``/``wait`` is a primitive that never ends; any
other behaviour is a primitive of the vocabulary (:mod:`.vocabulary`). Conditions
become :class:`Guard` terms resolved in the program's final scope, with ``self``
bound to the object and behaviour parameters bound to the call's arguments (only
those a guard reads are evaluated; they must not be random, as Scenic draws a
behaviour's arguments once per call and a guard must be memoryless).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..scenic import ir
from ..scene import expressions
from ..scene.dependencies import random_leaves
from ..scene.program import ProgramObject
from ..scene.resolve import Resolver, source_text
from ..scene.terms import Term
from ..scene.values import Instance
from . import hfsm as H
from .vocabulary import Vocabulary, primitive_name


@dataclass(frozen=True, eq=False)
class Guard:
    """A condition of the program: its term, its negation, the program objects whose observed
    features it reads (sorted), its source text and place."""

    index: int
    condition: Term
    negation: Term
    objects: tuple[str, ...]
    text: str
    span: ir.Span

    @property
    def is_random(self) -> bool:
        return bool(random_leaves(self.condition))


@dataclass(frozen=True)
class Thunk:
    """A behaviour argument, evaluated only if a guard reads it: expression and the caller's bindings."""

    node: ir.Node
    bindings: dict[str, Thunk]


@dataclass
class Translator:
    """Translates the behaviours of one resolved program; :meth:`hfsm` per program object."""

    resolver: Resolver
    vocabulary: Vocabulary
    guards: list[Guard] = field(default_factory=list)
    _by_term: dict[Term, Guard] = field(default_factory=dict)

    def error(self, message: str, node: ir.Node):
        return self.resolver.error(message, node)

    def hfsm(self, obj: ProgramObject) -> H.Hfsm:
        if obj.behaviour is None:
            return H.Hfsm(obj.name, None, None, ())
        used: set[int] = set()
        root = self.call(obj.behaviour, {}, obj.name, (), used)
        return H.Hfsm(obj.name, obj.behaviour.function, root, tuple(sorted(used)))

    # ---------------------------------------------------------------- behaviours
    def call(self, call: ir.Call, bindings: dict[str, Thunk], obj: str, stack: tuple[str, ...], used: set[int]):
        definition = self.resolver.behaviours.get(call.function)
        if definition is None:
            if call.function in bindings or call.function in self.resolver.scope:
                raise self.error(f"{call.function!r} is not a behaviour", call)
            name = primitive_name(call.function)
            if name not in self.vocabulary.entries:
                raise self.error(
                    f"unknown behaviour {call.function}: the program does not define it and the vocabulary"
                    f" ({Path(self.vocabulary.source).name}) has no primitive {name!r}; add it to a --vocabulary file",
                    call,
                )
            primitive = self.vocabulary.primitive(name)
            return H.BaseState(primitive.name, primitive.ends)
        if call.function in stack:
            raise self.error(f"behaviour {call.function} runs itself (recursion is not supported)", call)
        if _is_primitive_body(definition.body):
            return H.BaseState(primitive_name(definition.name), ends=False)
        inner = self.arguments(definition, call, bindings)
        return self.block(definition.body, inner, obj, (*stack, call.function), used)

    def arguments(self, definition: ir.BehaviourDef, call: ir.Call, bindings: dict[str, Thunk]) -> dict[str, Thunk]:
        if len(call.args) > len(definition.params):
            raise self.error(f"{definition.name} takes {len(definition.params)} arguments", call)
        given: dict[str, ir.Node] = dict(zip(definition.params, call.args))
        for name, value in call.keywords:
            if name not in definition.params or name in given:
                raise self.error(f"{definition.name} has no (other) parameter {name!r}", value)
            given[name] = value
        found = {}
        for name, default in zip(definition.params, definition.defaults):
            if name in given:
                found[name] = Thunk(given[name], bindings)
            elif default is not None:
                found[name] = Thunk(default, {})
            else:
                raise self.error(f"{definition.name} needs a value for its parameter {name!r}", call)
        return found

    def block(self, body: tuple[ir.Node, ...], bindings: dict[str, Thunk], obj: str, stack, used) -> H.State:
        states = tuple(self.statement(s, bindings, obj, stack, used) for s in body)
        return states[0] if len(states) == 1 else H.Sequence(states)

    def statement(self, node: ir.Node, bindings: dict[str, Thunk], obj: str, stack, used) -> H.State:
        if isinstance(node, ir.Do):
            return self.call(node.behaviour, bindings, obj, stack, used)
        if isinstance(node, ir.DoUntil):
            child = self.call(node.behaviour, bindings, obj, stack, used)
            guard = self.guard(node.condition, bindings, obj, used)
            return H.DoUntil(child, guard, f"do {node.behaviour.function} until (line {node.span.line})")
        if isinstance(node, ir.DoFor):
            child = self.call(node.behaviour, bindings, obj, stack, used)
            amount = self.constant(node.amount, bindings, obj)
            name = f"do {node.behaviour.function} for {amount:g} {node.unit} (line {node.span.line})"
            return H.DoFor(child, amount, node.unit, name)
        if isinstance(node, ir.TryInterrupt):
            body = self.block(node.body, bindings, obj, stack, used)
            written = [
                (self.guard(h.condition, bindings, obj, used), self.block(h.body, bindings, obj, stack, used))
                for h in node.handlers
            ]
            names = [f"interrupt (line {h.span.line})" for h in node.handlers]
            # Scenic checks the handler written last first (scenic/syntax/compiler.py reverses them)
            return H.TryInterrupt(
                body, tuple(reversed(written)), f"try (line {node.span.line})", tuple(reversed(names))
            )
        if isinstance(node, (ir.Take, ir.Forever)):
            raise self.error(
                "'take', 'wait' and 'while True' are supported only as a whole primitive behaviour "
                "('while True:' of take/wait)",
                node,
            )
        raise self.error(f"{type(node).__name__} is not supported in a behaviour", node)

    # ---------------------------------------------------------------- conditions
    def guard(self, node: ir.Node, bindings: dict[str, Thunk], obj: str, used: set[int]) -> int:
        condition = expressions.to_bool(self.resolver, self.evaluate(node, bindings, obj), node)
        known = self._register(condition, node)
        used.add(known.index)
        return known.index

    def condition(self, node: ir.Node, scope: dict[str, Any]) -> int:
        """The guard of a condition of a temporal requirement stated in ``scope`` (see
        :mod:`.temporal`); one reading a random value is an error (Scenic draws it once per scene)."""
        r = self.resolver
        saved = r.scope
        try:
            r.scope = dict(scope)
            condition = expressions.to_bool(r, expressions.evaluate(r, node), node)
        finally:
            r.scope = saved
        known = self._register(condition, node)
        if known.is_random:
            raise self.error(
                "a condition of a temporal requirement cannot read a random value: Scenic draws it once "
                "per scene, so the monitor would need memory; give a constant",
                node,
            )
        return known.index

    def _register(self, condition: Term, node: ir.Node) -> Guard:
        """The guard of a condition term (one per distinct term)."""
        known = self._by_term.get(condition)
        if known is None:
            f = self.resolver.f
            negation = f.op("not", condition, kind="bool")
            objects = tuple(sorted({leaf.value[0] for leaf in condition.leaves() if leaf.op == "observed"}))
            text = source_text(self.resolver.program, node.span)
            known = Guard(len(self.guards), condition, negation, objects, text, node.span)
            self.guards.append(known)
            self._by_term[condition] = known
        return known

    def constant(self, node: ir.Node, bindings: dict[str, Thunk], obj: str) -> float:
        value = expressions.to_num(self.resolver, self.evaluate(node, bindings, obj), node)
        if not value.is_const:
            raise self.error("a 'for' duration must be a constant number", node)
        if float(value.value) < 0:
            raise self.error("a 'for' duration cannot be negative", node)
        return float(value.value)

    def evaluate(self, node: ir.Node, bindings: dict[str, Thunk], obj: str) -> Any:
        """The value of ``node`` with ``self`` = the object and the parameters it reads bound."""
        r = self.resolver
        saved = dict(r.scope)
        try:
            r.scope["self"] = _instance(r, obj)
            for name in _names(node) & set(bindings):
                r.scope[name] = self.argument(name, bindings[name], obj)
            return expressions.evaluate(r, node)
        finally:
            r.scope = saved

    def argument(self, name: str, thunk: Thunk, obj: str) -> Any:
        value = self.evaluate(thunk.node, thunk.bindings, obj)
        if isinstance(value, Term) and random_leaves(value):
            raise self.error(
                f"the behaviour argument {name!r} is random: Scenic draws it once per call, so a guard "
                "reading it would need memory; give a constant",
                thunk.node,
            )
        return value


def _is_primitive_body(body: tuple[ir.Node, ...]) -> bool:
    return len(body) == 1 and isinstance(body[0], ir.Forever) and all(isinstance(s, ir.Take) for s in body[0].body)


def _instance(r: Resolver, name: str) -> Instance:
    return next(i for i in r.instances if i.name == name)


def _names(node: ir.Node) -> set[str]:
    """The plain names an expression reads."""
    found: set[str] = set()
    stack: list[Any] = [node]
    while stack:
        item = stack.pop()
        if isinstance(item, ir.Name):
            found.add(item.id)
        elif isinstance(item, ir.Node):
            stack.extend(getattr(item, f) for f in item.__dataclass_fields__ if f != "span")
        elif isinstance(item, tuple):
            stack.extend(item)
    return found
