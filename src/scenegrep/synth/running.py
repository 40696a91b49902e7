"""Which Scenic behaviours are running, observed during a simulation.

Scenic has no public API naming the sub-behaviour an agent is executing, so this module reads
it from the generators Scenic runs (private to Scenic 3.1.1, pinned): an agent's behaviour
holds its generator in ``_runningIterator``; a ``do`` statement delegates to the
sub-behaviour's generator (``gi_yieldfrom``); every generator frame of a behaviour body has the
running behaviour in its local ``_Scenic_current_behavior``; a ``try``/``interrupt`` statement
runs in a ``runTryInterrupt`` frame whose local ``block`` is the block that ran last, with its
generator in ``block.runningIterator``.

:func:`observe_steps` calls a function at every time step of every simulation started inside
it, after all agents have chosen their actions and before the physics runs: the objects then
have their state at the start of the step, and each behaviour stack is the one that chose the
step's actions.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any

STATIONARY = "Stationary"
"""The label of an object that runs no behaviour (none given, or finished)."""

SUFFIX = "Behavior"


def behaviour_stack(obj: Any) -> tuple[str, ...]:
    """Class names of the behaviours an object is running, outermost first (empty when it has
    none or its behaviour has finished)."""
    behaviour = getattr(obj, "behavior", None)
    iterator = None if behaviour is None else behaviour._runningIterator
    stack: list[Any] = []
    while iterator is not None:
        frame = getattr(iterator, "gi_frame", None)
        if frame is None:  # finished generator, or not a generator
            break
        current = frame.f_locals.get("_Scenic_current_behavior")
        if current is not None and (not stack or stack[-1] is not current):
            stack.append(current)
        if frame.f_code.co_name == "runTryInterrupt":
            block = frame.f_locals.get("block")
            iterator = None if block is None else block.runningIterator
        else:
            iterator = iterator.gi_yieldfrom
    return tuple(type(b).__name__ for b in stack)


def primitive_label(stack: tuple[str, ...]) -> str:
    """The primitive behaviour of a stack: its innermost behaviour's name without the
    ``Behavior`` suffix (``FollowLaneBehavior`` -> ``FollowLane``), :data:`STATIONARY` when empty."""
    if not stack:
        return STATIONARY
    name = stack[-1]
    return name[: -len(SUFFIX)] if name.endswith(SUFFIX) and len(name) > len(SUFFIX) else name


@contextlib.contextmanager
def observe_steps(callback: Callable[[Any], None]) -> Iterator[None]:
    """Within the block, ``callback(simulation)`` runs at every step of every Scenic simulation
    (see the module docstring); the hook is removed on exit."""
    from scenic.core.simulators import Simulation

    original = Simulation.executeActions

    def execute_actions(self: Any, all_actions: Any) -> None:
        callback(self)
        original(self, all_actions)

    Simulation.executeActions = execute_actions
    try:
        yield
    finally:
        Simulation.executeActions = original
