"""Hierarchical finite state machines of behaviours (seed 000 §4.2–4.3, Fig. 2) and one step of them.

A behaviour compiles (:mod:`.translate`) to a tree of states: :class:`BaseState`
(a primitive behaviour, output = its name), :class:`Sequence`, :class:`DoUntil`
(``do X`` is X itself), :class:`DoFor` and :class:`TryInterrupt`. A *configuration*
is the hashable record of which states are active (a nested tuple; ``None`` for a
state not yet started). One step runs as Scenic 3.1.1 runs a behaviour
(``scenic/core/dynamics/invocables.py``):

* a ``try`` checks its handlers in priority order before each step (Scenic gives
  the handler written last the highest priority): a running handler runs on, a
  higher one whose condition holds pre-empts it (the pre-empted one stays
  suspended), and the body runs only when no handler is enabled or
  running; a finished handler lets the selection run again in the same step; a
  finished body ends the ``try``;
* ``until`` conditions are checked before each step, including the first; a met
  condition ends the statement and the next one runs in the same step;
* ``do X for T`` runs X while fewer than T steps (or T seconds) have elapsed since it
  started, counting the steps during which a handler suspended it (simulation time);
* a primitive may end at any step (its end is not observable) unless the
  vocabulary says it never ends; a statement that ends hands the step to the next.

Guards are three-valued per step (:data:`CAN_TRUE` | :data:`CAN_FALSE`): an
unobserved random variable is drawn afresh at each evaluation, so a guard can be
both, and the step is then nondeterministic. :meth:`Hfsm.step` returns every
(output, next configuration) pair a step can produce.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from .vocabulary import STATIONARY

CAN_TRUE = 1
CAN_FALSE = 2
BOTH = CAN_TRUE | CAN_FALSE

Config = Any
"""A configuration: nested tuples of ints, ``None`` (not started) and :data:`TERMINATED`."""

RUNNING = 0
TERMINATED = "terminated"
"""The configuration of an HFSM whose top-level behaviour has ended (it then outputs Stationary)."""


@dataclass(frozen=True)
class StepInputs:
    """What a step reads: each guard's value (bit mask of CAN_TRUE, CAN_FALSE) and the frame period (s)."""

    guards: tuple[int, ...]
    period: float


@dataclass(frozen=True)
class Output:
    """One outcome of a step: the primitive output and the configuration after the step."""

    label: str
    config: Config


ENDED = None
"""The outcome of a state that ends during the step without producing an output."""

Outcome = Output | None


class State:
    """A state of an HFSM; ``name`` says what it is in the program's words."""

    name: str

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        """Every outcome of one step from ``config`` (``None``: the state starts now)."""
        raise NotImplementedError

    def path(self, config: Config) -> list[str]:
        """The names of the active states from this one down to the running base state."""
        raise NotImplementedError

    def tick(self, config: Config, step: StepInputs) -> Config:
        """``config`` after a step during which this state was suspended by an interrupt handler:
        simulation time still passes for the ``for`` statements inside it."""
        return config

    def base_labels(self) -> set[str]:
        """The outputs of every base state below this one."""
        raise NotImplementedError


@dataclass(frozen=True)
class BaseState(State):
    """A primitive behaviour: outputs its ``label``; can end at any step if ``ends``."""

    label: str
    ends: bool

    @property
    def name(self) -> str:  # type: ignore[override]
        return self.label

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        yield Output(self.label, RUNNING)
        if self.ends:
            yield ENDED

    def path(self, config: Config) -> list[str]:
        return [self.label]

    def base_labels(self) -> set[str]:
        return {self.label}


@dataclass(frozen=True)
class Sequence(State):
    """Statements run one after the other; configuration (index, child configuration)."""

    children: tuple[State, ...]
    name: str = "sequence"

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        index, child = (0, None) if config is None else config
        yield from self._from(index, child, step)

    def _from(self, index: int, child: Config, step: StepInputs) -> Iterator[Outcome]:
        for outcome in self.children[index].run(child, step):
            if outcome is not ENDED:
                yield Output(outcome.label, (index, outcome.config))
            elif index + 1 < len(self.children):
                yield from self._from(index + 1, None, step)
            else:
                yield ENDED

    def path(self, config: Config) -> list[str]:
        index, child = config
        return self.children[index].path(child)

    def tick(self, config: Config, step: StepInputs) -> Config:
        if config is None:
            return None
        index, child = config
        return index, self.children[index].tick(child, step)

    def base_labels(self) -> set[str]:
        return set().union(*(c.base_labels() for c in self.children))


@dataclass(frozen=True)
class DoUntil(State):
    """``do X until C``: ends (before X steps) whenever guard ``guard`` can hold; configuration = X's."""

    child: State
    guard: int
    name: str

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        value = step.guards[self.guard]
        if value & CAN_TRUE:
            yield ENDED
        if value & CAN_FALSE:
            yield from self.child.run(config, step)

    def path(self, config: Config) -> list[str]:
        return [self.name, *self.child.path(config)]

    def tick(self, config: Config, step: StepInputs) -> Config:
        return self.child.tick(config, step)

    def base_labels(self) -> set[str]:
        return self.child.base_labels()


@dataclass(frozen=True)
class DoFor(State):
    """``do X for amount unit`` (unit ``steps`` or ``seconds``); configuration (elapsed steps, X's)."""

    child: State
    amount: float
    unit: str
    name: str

    def limit(self, period: float) -> float:
        """The number of steps X may run (Scenic compares elapsed steps with seconds / timestep); a
        quotient within 1e-6 of a whole number is that number (timestamps carry rounding errors)."""
        if self.unit == "steps":
            return self.amount
        steps = self.amount / period
        return float(round(steps)) if abs(steps - round(steps)) < 1e-6 else steps

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        elapsed, child = (0, None) if config is None else config
        if elapsed >= self.limit(step.period):
            yield ENDED
            return
        for outcome in self.child.run(child, step):
            yield ENDED if outcome is ENDED else Output(outcome.label, (elapsed + 1, outcome.config))

    def path(self, config: Config) -> list[str]:
        return [f"{self.name} (step {config[0]})", *self.child.path(config[1])]

    def tick(self, config: Config, step: StepInputs) -> Config:
        if config is None:
            return None
        elapsed, child = config
        return min(elapsed + 1, math.ceil(self.limit(step.period))), self.child.tick(child, step)

    def base_labels(self) -> set[str]:
        return self.child.base_labels()


@dataclass(frozen=True)
class TryInterrupt(State):
    """``try: body`` with handlers (guard index, handler state) in priority order, highest first
    (Scenic's: the handler written last first), their names, and a configuration (body
    configuration, per handler its configuration or None when not running)."""

    body: State
    handlers: tuple[tuple[int, State], ...]
    name: str
    handler_names: tuple[str, ...] = ()

    def run(self, config: Config, step: StepInputs) -> Iterator[Outcome]:
        body, running = (None, (None,) * len(self.handlers)) if config is None else config
        yield from self._select(body, running, step, frozenset())

    def _select(self, body: Config, running: tuple, step: StepInputs, seen: frozenset) -> Iterator[Outcome]:
        key = (body, running)
        if key in seen:  # a handler that ends without a step, chosen again: no new outcome
            return
        seen = seen | {key}
        for j, (guard, _) in enumerate(self.handlers):
            if running[j] is not None:
                yield from self._handler(j, running[j], body, running, step, seen)
                return
            value = step.guards[guard]
            if value & CAN_TRUE:
                yield from self._handler(j, None, body, running, step, seen)
            if not value & CAN_FALSE:
                return
        for outcome in self.body.run(body, step):
            yield ENDED if outcome is ENDED else Output(outcome.label, (outcome.config, running))

    def _handler(
        self, j: int, config: Config, body: Config, running: tuple, step: StepInputs, seen: frozenset
    ) -> Iterator[Outcome]:
        handler = self.handlers[j][1]
        for outcome in handler.run(config, step):
            if outcome is ENDED:
                yield from self._select(body, running[:j] + (None,) + running[j + 1 :], step, seen)
            else:
                suspended = tuple(
                    h.tick(c, step) if c is not None and k != j else c
                    for k, ((_, h), c) in enumerate(zip(self.handlers, running))
                )
                after = suspended[:j] + (outcome.config,) + suspended[j + 1 :]
                yield Output(outcome.label, (self.body.tick(body, step), after))

    def tick(self, config: Config, step: StepInputs) -> Config:
        if config is None:
            return None
        body, running = config
        ticked = tuple(None if c is None else h.tick(c, step) for (_, h), c in zip(self.handlers, running))
        return self.body.tick(body, step), ticked

    def path(self, config: Config) -> list[str]:
        body, running = config
        for j, (_, handler) in enumerate(self.handlers):
            if running[j] is not None:
                label = self.handler_names[j] if self.handler_names else f"interrupt {j + 1}"
                return [f"{self.name}: {label}", *handler.path(running[j])]
        return [f"{self.name}: body", *self.body.path(body)]

    def base_labels(self) -> set[str]:
        return self.body.base_labels().union(*(h.base_labels() for _, h in self.handlers))


@dataclass(frozen=True)
class Hfsm:
    """The HFSM of one program object: its behaviour's root state (None: no behaviour, so it
    outputs Stationary) and the indices of the guards it reads."""

    obj: str
    behaviour: str | None
    root: State | None
    guards: tuple[int, ...]

    def outputs(self) -> tuple[str, ...]:
        """Every output the HFSM can produce, sorted (Stationary included: it follows the end)."""
        labels = set() if self.root is None else self.root.base_labels()
        return tuple(sorted(labels | {STATIONARY}))

    def step(self, config: Config, inputs: StepInputs) -> list[Output]:
        """Every (output, next configuration) of one step from ``config`` (``None``: initial)."""
        if self.root is None or config == TERMINATED:
            return [Output(STATIONARY, TERMINATED)]
        found = []
        for outcome in self.root.run(config, inputs):
            found.append(Output(STATIONARY, TERMINATED) if outcome is ENDED else outcome)
        return found

    def path(self, config: Config) -> str:
        """The active states of a configuration, outermost first (for explanations)."""
        if self.root is None:
            return "Stationary (no behaviour)"
        if config == TERMINATED:
            return f"{self.behaviour} ended: Stationary"
        return " > ".join([self.behaviour or "", *self.root.path(config)])
