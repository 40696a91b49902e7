"""Temporal requirements of scenario queries (Scenic 3's ``require always/eventually/next/until/implies``).

Semantics. The window of m frames is the run. A temporal requirement holds over the window
iff its formula holds at the window's first frame in linear temporal logic over finite traces
with Scenic 3.1.1's end-of-run verdicts (``rv_ltl``, used by ``scenic.core.propositions``):
``always C`` holds iff C holds at every frame of the window; ``eventually C`` iff at some
frame; ``C until D`` is *strong*: D holds at some frame and C at every frame before it
(rv_ltl answers "presumably false" when D never came, and Scenic rejects a run ending on a
falsy verdict); ``next C`` is *strong*: at the last frame it is false (rv_ltl: presumably
false); ``A implies B`` is ``not A or B``; ``and``/``or``/``not`` are per frame. Scenic
also rejects a run as soon as a verdict is definitely false; a definitely false verdict stays
false on every extension, so that never rejects a run whose whole-run verdict is true.

Conditions under the operators (the maximal non-temporal parts, Scenic's atomic propositions)
are :class:`~.translate.Guard`\\ s, decided per frame like behaviour guards (three-valued: an
undecided frame may be either). A condition reading a random value is an error: Scenic draws
it once per scene, so the monitor would need memory.

Monitor. The formula, in negation normal form, is progressed frame by frame: the state is a
disjunction of clauses, each a set of *next obligations* — ``X f`` (f must hold at the next
frame, which must exist) or ``W f`` (weak: if there is a next frame). A clause is a
configuration of a nondeterministic automaton (a frame where a condition can be both true and
false takes both), and :class:`Monitor` is its lazy DFA (:class:`~.automaton.LazyDfa`), so
matching is the same one pass over frames as the HFSMs', with the same state budget and the
same fallback. A run is accepted when, after the window's last frame, some clause holds only
weak obligations.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from itertools import product
from typing import Any

from ..scene.resolve import source_text, is_temporal
from ..scenic import ir
from .automaton import MAX_STATES, LazyDfa
from .hfsm import CAN_FALSE, CAN_TRUE
from .translate import Translator

MAX_CONDITIONS = 24
"""At most this many conditions in one temporal requirement (a frame's symbol holds 2 bits each)."""

ATOM, NOT_ATOM, AND, OR, NEXT, WEAK_NEXT, UNTIL, RELEASE, ALWAYS, EVENTUALLY = (
    "atom",
    "not atom",
    "and",
    "or",
    "next",
    "weak next",
    "until",
    "release",
    "always",
    "eventually",
)


@dataclass(frozen=True)
class Formula:
    """A temporal formula in negation normal form: ``op``, its operands, and for (negated) atoms
    the index of the guard that decides them."""

    op: str
    args: tuple[Formula, ...] = ()
    guard: int = -1


Clause = frozenset[Formula]
"""A conjunction of next obligations (formulas whose op is NEXT or WEAK_NEXT); empty = true."""

Dnf = frozenset[Clause]
"""A disjunction of clauses; empty = false."""

TRUE: Dnf = frozenset({frozenset()})
FALSE: Dnf = frozenset()


def normal_form(node: ir.Node, negate: bool, atom: Any) -> Formula:
    """The negation normal form of a requirement's condition (``not`` pushed to the conditions);
    ``atom(node)`` gives the guard index of a non-temporal part."""
    if isinstance(node, ir.Temporal):
        parts = node.operands
        if node.op == "always":
            return Formula(EVENTUALLY if negate else ALWAYS, (normal_form(parts[0], negate, atom),))
        if node.op == "eventually":
            return Formula(ALWAYS if negate else EVENTUALLY, (normal_form(parts[0], negate, atom),))
        if node.op == "next":
            return Formula(WEAK_NEXT if negate else NEXT, (normal_form(parts[0], negate, atom),))
        if node.op == "until":
            left, right = (normal_form(p, negate, atom) for p in parts)
            return Formula(RELEASE if negate else UNTIL, (left, right))
        hypothesis, conclusion = normal_form(parts[0], not negate, atom), normal_form(parts[1], negate, atom)
        return Formula(AND if negate else OR, (hypothesis, conclusion))
    if isinstance(node, ir.BoolOp) and is_temporal(node):
        op = {"and": OR, "or": AND}[node.op] if negate else {"and": AND, "or": OR}[node.op]
        return Formula(op, tuple(normal_form(o, negate, atom) for o in node.operands))
    if isinstance(node, ir.Unary) and node.op == "not" and is_temporal(node):
        return normal_form(node.operand, not negate, atom)
    return Formula(NOT_ATOM if negate else ATOM, guard=atom(node))


def _conjoin(a: Dnf, b: Dnf) -> Dnf:
    return minimal(frozenset(x | y for x in a for y in b))


def minimal(dnf: Dnf) -> Dnf:
    """The clauses of ``dnf`` that contain no other clause (the same disjunction)."""
    return frozenset(c for c in dnf if not any(d < c for d in dnf))


@lru_cache(maxsize=1 << 16)
def progress(f: Formula, values: frozenset[tuple[int, bool]]) -> Dnf:
    """What must hold from the next frame on for ``f`` to hold at a frame whose conditions have
    ``values`` (guard index, truth)."""
    op = f.op
    if op in (ATOM, NOT_ATOM):
        return TRUE if ((f.guard, True) in values) == (op == ATOM) else FALSE
    if op in (NEXT, WEAK_NEXT):
        return frozenset({frozenset({f})})
    if op == AND:
        found = TRUE
        for a in f.args:
            found = _conjoin(found, progress(a, values))
        return found
    if op == OR:
        return minimal(frozenset().union(*(progress(a, values) for a in f.args)))
    if op == ALWAYS:
        return _conjoin(progress(f.args[0], values), frozenset({frozenset({Formula(WEAK_NEXT, (f,))})}))
    if op == EVENTUALLY:
        return minimal(progress(f.args[0], values) | {frozenset({Formula(NEXT, (f,))})})
    left, right = (progress(a, values) for a in f.args)
    if op == UNTIL:
        return minimal(progress(f.args[1], values) | _conjoin(left, frozenset({frozenset({Formula(NEXT, (f,))})})))
    # RELEASE: right holds now, and left holds now or the release goes on (weakly)
    return _conjoin(right, minimal(left | {frozenset({Formula(WEAK_NEXT, (f,))})}))


@dataclass(frozen=True, eq=False)
class TemporalRequirement:
    """A compiled temporal requirement: its formula, the guards of its conditions (sorted), the
    program objects they read (sorted), its source text and place."""

    formula: Formula
    guards: tuple[int, ...]
    objects: tuple[str, ...]
    text: str
    span: ir.Span


def compile_requirement(translator: Translator, node: ir.Require, scope: dict[str, Any]) -> TemporalRequirement:
    """A temporal requirement stated in ``scope`` (the resolver's, at the statement), its
    conditions registered as the translator's guards."""
    used: set[int] = set()

    def atom(part: ir.Node) -> int:
        guard = translator.condition(part, scope)
        used.add(guard)
        return guard

    formula = normal_form(node.condition, False, atom)
    if len(used) > MAX_CONDITIONS:
        raise translator.error(f"a temporal requirement may have at most {MAX_CONDITIONS} conditions", node)
    objects = sorted(set().union(*(translator.guards[g].objects for g in used)))
    text = f"require {source_text(translator.resolver.program, node.condition.span)}"
    return TemporalRequirement(formula, tuple(sorted(used)), tuple(objects), text, node.span)


class Monitor(LazyDfa):
    """The lazy DFA of one temporal requirement: a configuration is a :data:`Clause`, the initial
    one obliges the formula at the first frame, a symbol is the requirement's guard values
    (2 bits each, in ``guards`` order, no label bits), a run must end in a clause of weak
    obligations only."""

    final_acceptance = True

    def __init__(self, requirement: TemporalRequirement, name: str, budget: int = MAX_STATES):
        self.requirement = requirement
        self.name = name
        self.guards = requirement.guards
        self.initial = frozenset({Formula(NEXT, (requirement.formula,))})
        super().__init__(budget)

    def step_config(self, config: Clause, symbol: int) -> frozenset[Clause]:
        """Every clause after one frame: each obligation progressed under each truth assignment
        the frame's guard values allow (both for a guard that can be true and false)."""
        choices = [
            [(g, v) for v, bit in ((True, CAN_TRUE), (False, CAN_FALSE)) if value & bit]
            for g, value in zip(self.guards, self.guard_values(symbol))
        ]
        found: set[Clause] = set()
        for values in product(*choices):
            valuation = frozenset(values)
            after = TRUE
            for obligation in config:
                after = _conjoin(after, progress(obligation.args[0], valuation))
            found |= after
        return minimal(frozenset(found))

    def step_set(self, configs: frozenset[Clause], symbol: int) -> frozenset[Clause]:
        return minimal(super().step_set(configs, symbol))

    def accepting(self, config: Clause) -> bool:
        return all(obligation.op == WEAK_NEXT for obligation in config)
