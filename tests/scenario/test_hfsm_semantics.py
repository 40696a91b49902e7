"""The HFSM step (:mod:`scenegrep.scenario.hfsm`) against a brute-force reference interpreter of Scenic 3.1.1.

The reference below does not use hfsm.py's run logic. It runs a behaviour, written as a small nested
structure, with Python generators in the style of Scenic's ``runTryInterrupt`` and
``_invokeSubBehavior`` (``scenic/core/dynamics/invocables.py``):

* ``("prim", label, ends)``: a primitive; outputs ``label`` each step; if ``ends`` it may end at any
  step, also before its first output;
* ``("seq", [child, ...])``: statements one after the other;
* ``("until", child, guard)``: ``do child until guard`` (Scenic: a try/interrupt whose handler aborts);
* ``("for", child, n)``: ``do child for n steps`` (Scenic: the same, with the condition
  ``currentTime - startTime >= n``);
* ``("try", body, [(guard, handler), ...])``: ``try: body`` with ``interrupt when guard: handler``, the
  handlers in runTryInterrupt's order, highest priority first (as :class:`TryInterrupt`; Scenic's
  compiler passes them in the reverse of the order they are written in).

Every nondeterministic choice (each guard evaluation, within the step's guard mask; each primitive's
choice to end or go on) comes from an explicit :class:`Choices` source, and :func:`enumerate_runs`
re-runs the program with every forced prefix of choices (depth first), so the reference yields the
exact set of output sequences. After the top-level behaviour ends the output is Stationary, as in
:class:`Hfsm`.

The tests: the HFSM's output sequences equal the reference's (hypothesis, random behaviours and guard
masks); the lazy DFA and windows.reach agree with the reference on random observed labels; the
reference agrees with Scenic 3.1.1 itself (DummySimulator) on deterministic behaviours; named rules as
explicit examples.
"""

from __future__ import annotations

import functools
import types
from collections.abc import Callable, Iterator

import numpy as np
from hypothesis import assume, event, given, settings
from hypothesis import strategies as st

from scenegrep.scenario.automaton import DEAD, INITIAL, Automaton, OverBudget, encode
from scenegrep.scenario.hfsm import (
    BOTH,
    CAN_FALSE,
    CAN_TRUE,
    TERMINATED,
    BaseState,
    DoFor,
    DoUntil,
    Hfsm,
    Output,
    Sequence,
    State,
    StepInputs,
    TryInterrupt,
)
from scenegrep.scenario.query import compile_scenario
from scenegrep.scenario.simulate import simulate_reach
from scenegrep.scenario.windows import table_reach

STATIONARY = "Stationary"
PERIOD = 0.1
N_GUARDS = 2
LABELS = ("A", "B", "C")

# --------------------------------------------------------------------------------------------------
# The reference interpreter
# --------------------------------------------------------------------------------------------------


class Pruned(Exception):
    """A run that took a needless loop within one step (see :func:`run_try_interrupt`); dropped."""


class Choices:
    """A source of choices: the forced prefix first, then always the first option; records every choice."""

    def __init__(self, forced: list[int]):
        self.forced = forced
        self.taken: list[tuple[int, int]] = []  # (index chosen, number of options)

    def pick(self, options: tuple):
        if len(options) == 1:
            return options[0]
        i = len(self.taken)
        k = self.forced[i] if i < len(self.forced) else 0
        self.taken.append((k, len(options)))
        return options[k]


def enumerate_runs(run: Callable[[Choices], object]) -> set:
    """The results of ``run`` over every sequence of choices."""
    results = set()
    forced: list[int] = []
    while True:
        choices = Choices(forced)
        results.add(run(choices))
        taken = choices.taken
        i = len(taken) - 1
        while i >= 0 and taken[i][0] + 1 >= taken[i][1]:
            i -= 1
        if i < 0:
            return results
        forced = [k for k, _ in taken[:i]] + [taken[i][0] + 1]


class World:
    """The simulation as the behaviour sees it: the step number and the guards' masks at each step."""

    def __init__(self, masks: list[tuple[int, ...]], choices: Choices, extra_rounds: int | None = None):
        self.masks = masks
        self.choices = choices
        self.time = 0
        self.extra_rounds = extra_rounds

    def guard(self, index: int) -> bool:
        """One evaluation of a guard: any truth value its mask at the current step allows."""
        mask = self.masks[self.time][index]
        options = ((True,) if mask & CAN_TRUE else ()) + ((False,) if mask & CAN_FALSE else ())
        return self.choices.pick(options)


FINISHED = "FINISHED"  # BlockConclusion.FINISHED
ABORT = "ABORT"  # BlockConclusion.ABORT


class InterruptBlock:
    """Scenic's InterruptBlock: a condition and a body started lazily, suspended between steps."""

    def __init__(self, condition, body):
        self.condition = condition
        self.body = body
        self.running_iterator = None

    def step(self):
        if self.running_iterator is None:
            it = self.body()
            if not isinstance(it, types.GeneratorType):
                return it, True
            self.running_iterator = it
        try:
            return next(self.running_iterator), False
        except StopIteration as stop:
            self.running_iterator = None
            return stop.value, True


def run_try_interrupt(world: World, body, conditions, handlers) -> Iterator[str]:
    """Scenic's runTryInterrupt, with two departures that leave the set of outcomes unchanged.

    * A running handler's condition is not evaluated (Scenic evaluates it, then ignores the value:
      ``isEnabled or isRunning``), which saves a needless choice.
    * A run is dropped (:class:`Pruned`) when a handler starts and finishes in the same round of the
      selection loop. Such a round ends in exactly the state it began in (the body is untouched until
      selected, the other handlers too, and the handler is idle again), so it is a loop: the same
      outputs follow without it. Scenic would itself loop forever if such a handler always finished
      at once. Without loops a step has at most ``len(handlers) + 1`` rounds, as each round that does
      not end the step clears a handler that was running before.

    With ``world.extra_rounds`` set, loops are kept instead and a run is dropped only when one step
    takes more than ``len(handlers) + 1 + world.extra_rounds`` rounds (to check the pruning above).
    """
    body_block = InterruptBlock(None, body)
    interrupts = [InterruptBlock(c, h) for c, h in zip(conditions, handlers)]
    rounds = 0
    while True:
        rounds += 1
        if world.extra_rounds is not None and rounds > len(handlers) + 1 + world.extra_rounds:
            raise Pruned
        block = body_block
        for interrupt in interrupts:
            if interrupt.running_iterator is not None or interrupt.condition():
                block = interrupt
                break
        was_running = block.running_iterator is not None
        result, concluded = block.step()
        if concluded:
            if result is FINISHED and block is not body_block:
                if not was_running and world.extra_rounds is None:
                    raise Pruned
                continue  # interrupt handler finished
            return result  # the try statement ends
        yield result
        rounds = 0


def behave(node, world: World) -> Iterator[str]:
    """A behaviour (nested structure) as a generator of one output per step; returns when it ends."""
    kind = node[0]
    if kind == "prim":
        _, label, ends = node
        while not (ends and world.choices.pick((False, True))):
            yield label
    elif kind == "seq":
        for child in node[1]:
            yield from behave(child, world)
    elif kind == "until":
        _, child, guard = node
        yield from do_with_modifier(child, world, lambda: world.guard(guard))
    elif kind == "for":
        _, child, amount = node
        start = world.time  # the step at which the statement starts (Scenic: currentTime)
        yield from do_with_modifier(child, world, lambda: world.time - start >= amount)
    elif kind == "try":
        _, body, handlers = node
        yield from run_try_interrupt(
            world,
            lambda: behave(body, world),
            [lambda g=g: world.guard(g) for g, _ in handlers],
            [lambda h=h: handler_body(h, world) for _, h in handlers],
        )
    else:
        raise ValueError(node)


def handler_body(node, world: World) -> Iterator[str]:
    """An interrupt handler: the behaviour, then FINISHED (the handler's block ends normally)."""
    yield from behave(node, world)
    return FINISHED


def do_with_modifier(child, world: World, condition) -> Iterator[str]:
    """``do child until/for``: Scenic's _invokeSubBehavior, a try whose only handler aborts it."""
    return run_try_interrupt(world, lambda: behave(child, world), [condition], [lambda: ABORT])


def reference_runs(tree, masks: list[tuple[int, ...]], extra_rounds: int | None = None) -> set[tuple[str, ...]]:
    """The outputs of every run of the reference interpreter, one per step of ``masks``; a run dropped
    (:class:`Pruned`) in a step gives only the outputs of the steps before."""

    def run(choices: Choices) -> tuple[str, ...]:
        world = World(masks, choices, extra_rounds)
        behaviour = behave(tree, world)
        outputs = []
        ended = False
        for t in range(len(masks)):
            world.time = t
            if not ended:
                try:
                    outputs.append(next(behaviour))
                except StopIteration:
                    ended = True
                except Pruned:
                    break
            if ended:
                outputs.append(STATIONARY)
        return tuple(outputs)

    return enumerate_runs(run)


def reference_sequences(tree, masks: list[tuple[int, ...]], extra_rounds: int | None = None) -> set[tuple[str, ...]]:
    """Every output sequence (one output per step of ``masks``) the reference interpreter can produce."""
    return {outputs for outputs in reference_runs(tree, masks, extra_rounds) if len(outputs) == len(masks)}


def reference_prefixes(tree, masks: list[tuple[int, ...]]) -> set[tuple[str, ...]]:
    """Every sequence of outputs of the first k steps (k = 0 .. len(masks)) the reference can produce.

    Not only the prefixes of :func:`reference_sequences`: where a handler's condition surely holds and
    the handler surely ends at once, Scenic loops forever in that step, so a run can stop short.
    """
    return {outputs[:k] for outputs in reference_runs(tree, masks) for k in range(len(outputs) + 1)}


# --------------------------------------------------------------------------------------------------
# The same behaviour as an HFSM
# --------------------------------------------------------------------------------------------------


def to_state(node) -> State:
    kind = node[0]
    if kind == "prim":
        return BaseState(node[1], node[2])
    if kind == "seq":
        return Sequence(tuple(to_state(child) for child in node[1]))
    if kind == "until":
        return DoUntil(to_state(node[1]), node[2], f"until g{node[2]}")
    if kind == "for":
        return DoFor(to_state(node[1]), node[2], "steps", f"for {node[2]} steps")
    if kind == "try":
        return TryInterrupt(to_state(node[1]), tuple((g, to_state(h)) for g, h in node[2]), "try")
    raise ValueError(node)


def guards_of(node) -> set[int]:
    kind = node[0]
    if kind == "prim":
        return set()
    if kind == "seq":
        return set().union(*(guards_of(child) for child in node[1]))
    if kind == "until":
        return {node[2]} | guards_of(node[1])
    if kind == "for":
        return guards_of(node[1])
    return guards_of(node[1]).union(*({g} | guards_of(h) for g, h in node[2]))


def to_hfsm(tree) -> Hfsm:
    return Hfsm("ego", "Behaviour", to_state(tree), tuple(sorted(guards_of(tree))))


def hfsm_sequences(tree, masks: list[tuple[int, ...]]) -> set[tuple[str, ...]]:
    """Every output sequence of the HFSM, by breadth-first simulation of (configuration, outputs) sets."""
    hfsm = to_hfsm(tree)
    frontier = {(None, ())}
    for mask in masks:
        inputs = StepInputs(tuple(mask), PERIOD)
        frontier = {(o.config, outputs + (o.label,)) for config, outputs in frontier for o in hfsm.step(config, inputs)}
    return {outputs for _, outputs in frontier}


# --------------------------------------------------------------------------------------------------
# Random behaviours and guard masks
# --------------------------------------------------------------------------------------------------

guard_indices = st.integers(0, N_GUARDS - 1)


@functools.cache
def behaviours(depth: int = 3, ends: bool = True) -> st.SearchStrategy:
    """Behaviour trees with at most ``depth`` levels of statements above the primitives; with ``ends``
    False every primitive is one that never ends."""
    primitives = st.tuples(st.just("prim"), st.sampled_from(LABELS), st.booleans() if ends else st.just(False))
    if depth == 0:
        return primitives
    sub = behaviours(depth - 1, ends)
    handler = st.tuples(guard_indices, sub)
    return st.one_of(
        primitives,
        st.tuples(st.just("seq"), st.lists(sub, min_size=1, max_size=3).map(tuple)),
        st.tuples(st.just("until"), sub, guard_indices),
        st.tuples(st.just("for"), sub, st.integers(0, 3)),
        st.tuples(st.just("try"), sub, st.lists(handler, min_size=1, max_size=2).map(tuple)),
    )


guard_masks = st.lists(st.tuples(*[st.sampled_from((CAN_TRUE, CAN_FALSE, BOTH))] * N_GUARDS), min_size=1, max_size=5)
certain_guard_masks = st.lists(st.tuples(*[st.sampled_from((CAN_TRUE, CAN_FALSE))] * N_GUARDS), min_size=1, max_size=5)


# --------------------------------------------------------------------------------------------------
# Scenic itself, for behaviours without nondeterminism
# --------------------------------------------------------------------------------------------------


def scenic_program(tree, masks: list[tuple[int, ...]]) -> str:
    """The behaviour as a Scenic program: guard g holds at the steps where its mask is CAN_TRUE, and a
    primitive (which must never end) records (step, label) in ``builtins.HFSM_SEMANTICS_LOG``."""
    helpers: list[str] = []

    def indent(lines: list[str]) -> list[str]:
        return ["    " + line for line in lines]

    def statements(node) -> list[str]:
        kind = node[0]
        if kind == "prim":
            assert not node[2], "Scenic runs only primitives that never end here"
            return [f'do Prim("{node[1]}")']
        if kind == "seq":
            return [line for child in node[1] for line in statements(child)]
        if kind == "until":
            return [f"do {invocation(node[1])} until G{node[2]}()"]
        if kind == "for":
            return [f"do {invocation(node[1])} for {node[2]} steps"]
        # Each block is a behaviour of its own (``do`` of a behaviour adds no step), as Scenic 3.1.1 fails to
        # compile some try statements nested in another's blocks ("no binding for nonlocal ...").
        lines = ["try:", f"    do {invocation(node[1])}"]
        for guard, handler in reversed(node[2]):  # Scenic gives priority to the handler written last
            lines += [f"interrupt when G{guard}():", f"    do {invocation(handler)}"]
        return lines

    def invocation(node) -> str:
        if node[0] == "prim":
            return f'Prim("{node[1]}")'
        body = statements(node)
        name = f"Node{len(helpers)}"
        helpers.extend([f"behavior {name}():", *indent(body)])
        return f"{name}()"

    top = ["behavior Top():", *indent(statements(tree))]
    lines = [
        "import builtins",
        "LOG = builtins.HFSM_SEMANTICS_LOG",
        "behavior Prim(label):",
        "    while True:",
        "        LOG.append((simulation().currentTime, label))",
        "        wait",
    ]
    for g in range(N_GUARDS):
        steps = tuple(t for t, mask in enumerate(masks) if mask[g] == CAN_TRUE)
        lines += [f"def G{g}():", f"    return simulation().currentTime in {steps!r}"]
    return "\n".join([*lines, *helpers, *top, "ego = new Object with behavior Top()", ""])


def run_scenic(source: str, steps: int, folder) -> tuple[str, ...]:
    """The outputs of Scenic 3.1.1 (DummySimulator) running a program whose primitives record (step, label)
    in ``builtins.HFSM_SEMANTICS_LOG``: the label of each step, Stationary where none was recorded."""
    import builtins

    import scenic
    from scenic.core.simulators import DummySimulator

    path = folder / f"behaviour{len(list(folder.iterdir()))}.scenic"
    path.write_text(source)
    builtins.HFSM_SEMANTICS_LOG = log = []
    try:
        scene, _ = scenic.scenarioFromFile(str(path)).generate(maxIterations=1)
        DummySimulator().simulate(scene, maxSteps=steps)
    finally:
        del builtins.HFSM_SEMANTICS_LOG
    recorded = [t for t, _ in log]
    assert len(recorded) == len(set(recorded)), log
    labels = dict(log)
    return tuple(labels.get(t, STATIONARY) for t in range(steps))


def scenic_outputs(tree, masks: list[tuple[int, ...]], folder) -> tuple[str, ...]:
    """The outputs of Scenic 3.1.1 running the behaviour, Stationary once it has ended."""
    return run_scenic(scenic_program(tree, masks), len(masks), folder)


# --------------------------------------------------------------------------------------------------
# Properties
# --------------------------------------------------------------------------------------------------


STATE_BUDGET = 300
"""The DFA states a test builds at most (nested tries can have thousands of hundreds of configurations)."""


def agrees(sequence: tuple[str, ...], observed: list[set[str]], k: int) -> bool:
    """Whether ``sequence`` shows, at each of its first ``k`` steps, a label of the observed set of the step."""
    return all(sequence[t] in observed[t] for t in range(k))


@settings(max_examples=200, deadline=None)
@given(tree=behaviours(), masks=guard_masks)
def test_hfsm_outputs_equal_the_reference(tree, masks):
    """Any behaviour, any guard masks: the HFSM's output sequences are exactly Scenic's."""
    assert hfsm_sequences(tree, masks) == reference_sequences(tree, masks)


@settings(max_examples=200, deadline=None)
@given(data=st.data(), tree=behaviours(), masks=guard_masks)
def test_automaton_and_windows_agree_with_the_reference(data, tree, masks):
    """The lazy DFA survives k steps iff some reference run shows the observed labels for its first k
    steps; the simulation of configuration sets (the DFA's fallback) and windows.reach over the DFA's
    table give every start frame the survival length of the reference restarted there (capped). (The
    table is not checked when it needs more than STATE_BUDGET states.)
    """
    hfsm = to_hfsm(tree)
    outputs = hfsm.outputs()
    n = len(masks)
    label_masks = data.draw(st.lists(st.integers(0, (1 << len(outputs)) - 1), min_size=n, max_size=n), "observed")
    observed = [{label for p, label in enumerate(outputs) if bits >> p & 1} for bits in label_masks]
    cap = data.draw(st.integers(1, 6), "cap")

    guard_codes = [np.array([mask[g] for mask in masks]) for g in hfsm.guards]
    symbols = encode(np.array(label_masks), guard_codes, len(outputs))
    automaton = Automaton(hfsm, N_GUARDS, PERIOD, STATE_BUDGET)

    prefixes = reference_prefixes(tree, masks)
    state = INITIAL
    for k in range(1, n + 1):
        state = automaton.next(state, int(symbols[k - 1]))
        expected = any(len(prefix) == k and agrees(prefix, observed, k) for prefix in prefixes)
        assert (state != DEAD) == expected, f"step {k}: observed {observed[:k]}, reference {sorted(prefixes)}"

    expected = []
    for i in range(n):
        suffix = reference_prefixes(tree, masks[i:])
        expected.append(max(len(p) for p in suffix if len(p) <= cap and agrees(p, observed[i:], len(p))))
    assert simulate_reach(automaton, symbols[None], cap)[0].tolist() == expected

    try:
        assert table_reach(automaton, symbols[None], cap)[0].tolist() == expected
    except OverBudget:
        event("the DFA table is over its budget: only the simulation is checked")


@settings(max_examples=60, deadline=None)
@given(tree=behaviours(ends=False), masks=certain_guard_masks)
def test_the_reference_agrees_with_scenic_itself(tmp_path_factory, tree, masks):
    """Behaviours whose primitives never end, guards surely true or false: Scenic 3.1.1 itself (run with
    its DummySimulator) produces the one output sequence of the reference. (Programs on which Scenic
    would loop forever within a step, where the reference has no sequence, are skipped.)"""
    expected = reference_sequences(tree, masks)
    assume(len(expected) == 1)
    assert {scenic_outputs(tree, masks, tmp_path_factory.mktemp("scenic"))} == expected


def test_scenic_itself_counts_the_steps_during_which_a_for_is_suspended(tmp_path):
    """Scenic 3.1.1 runs ``try: do A for 2 steps / interrupt when step == 1: do B for 1 steps`` as A, B,
    then ends (the ``for`` has seen 2 steps pass), and so does the reference (for the HFSM see
    :func:`test_for_counts_the_steps_during_which_it_is_suspended`)."""
    tree = ("try", ("for", ("prim", "A", False), 2), ((0, ("for", ("prim", "B", False), 1)),))
    masks = [(CAN_FALSE, CAN_FALSE), (CAN_TRUE, CAN_FALSE), (CAN_FALSE, CAN_FALSE), (CAN_FALSE, CAN_FALSE)]
    assert scenic_outputs(tree, masks, tmp_path) == ("A", "B", STATIONARY, STATIONARY)
    assert reference_sequences(tree, masks) == {("A", "B", STATIONARY, STATIONARY)}


@settings(max_examples=100, deadline=None)
@given(tree=behaviours(depth=2), masks=guard_masks.filter(lambda masks: len(masks) <= 3))
def test_the_reference_loses_nothing_by_pruning_loops(tree, masks):
    """The reference with loops pruned equals the reference that allows an extra round per step."""
    assert reference_sequences(tree, masks) == reference_sequences(tree, masks, extra_rounds=1)


def test_the_choice_enumeration_visits_every_choice_sequence():
    """The depth-first enumeration of forced prefixes reaches every combination of choices, also when
    the choices asked depend on earlier ones."""

    def run(choices: Choices):
        first = choices.pick(("a", "b", "c"))
        return (first, choices.pick((1, 2))) if first == "b" else (first,)

    assert enumerate_runs(run) == {("a",), ("b", 1), ("b", 2), ("c",)}


# --------------------------------------------------------------------------------------------------
# Named rules
# --------------------------------------------------------------------------------------------------

T, F, X = CAN_TRUE, CAN_FALSE, BOTH
S = STATIONARY


def check(tree, masks: list[tuple[int, ...]], expected: set[tuple[str, ...]]):
    """The reference (Scenic) gives ``expected``, and so does the HFSM."""
    assert reference_sequences(tree, masks) == expected, "the reference interpreter"
    assert hfsm_sequences(tree, masks) == expected, "the HFSM"


def test_until_is_checked_before_the_first_step():
    """``do A until g`` with g true at the first step never runs A: the next statement runs at once."""
    tree = ("seq", (("until", ("prim", "A", False), 0), ("prim", "B", False)))
    check(tree, [(T,), (F,), (X,)], {("B", "B", "B")})
    check(tree, [(F,), (T,), (F,)], {("A", "B", "B")})
    check(tree, [(F,), (X,), (F,)], {("A", "B", "B"), ("A", "A", "A")})


def test_for_2_steps_runs_exactly_2_steps():
    """``do A for 2 steps`` outputs A twice, then the next statement runs; ``for 0 steps`` skips A."""
    check(("seq", (("for", ("prim", "A", False), 2), ("prim", "B", False))), [()] * 4, {("A", "A", "B", "B")})
    check(("seq", (("for", ("prim", "A", False), 0), ("prim", "B", False))), [()] * 2, {("B", "B")})
    ending = {("A", "A", "B"), ("A", "B", "B"), ("B", "B", "B")}  # A may end sooner
    check(("seq", (("for", ("prim", "A", True), 2), ("prim", "B", False))), [()] * 3, ending)


def test_an_earlier_handler_preempts_a_running_later_one_which_then_resumes():
    """Handler 2 (B until g2, then C) runs; handler 1 (A for 1 step) pre-empts it for one step; when
    handler 1 ends, in the same step, handler 2 resumes where it was (C), it does not restart (B)."""
    later = ("seq", (("until", ("prim", "B", False), 2), ("prim", "C", False)))
    tree = ("try", ("prim", "D", False), ((0, ("for", ("prim", "A", False), 1)), (1, later)))
    masks = [(F, T, F), (F, F, T), (T, F, F), (F, F, F), (F, T, F)]
    check(tree, masks, {("B", "C", "A", "C", "C")})


def test_the_body_resumes_after_a_handler_finishes():
    """The body (B until g1, then C) is interrupted by A for 1 step; in the step the handler ends the
    body runs again from where it was (C), not from its start (B)."""
    body = ("seq", (("until", ("prim", "B", False), 1), ("prim", "C", False)))
    tree = ("try", body, ((0, ("for", ("prim", "A", False), 1)),))
    check(tree, [(F, F), (F, T), (T, F), (F, F), (F, F)], {("B", "C", "A", "C", "C")})


def test_a_running_handler_runs_on_while_its_condition_holds_again():
    """A handler whose condition holds again while it runs is not restarted: it runs on."""
    handler = ("seq", (("until", ("prim", "A", False), 1), ("prim", "B", False)))
    tree = ("try", ("prim", "C", False), ((0, handler),))
    check(tree, [(T, F), (T, T), (T, F)], {("A", "B", "B")})


def test_a_never_ending_primitive_never_ends():
    """A primitive with ends=False outputs its label at every step; with ends=True it may end at any
    step, also before its first output (then the next statement, or Stationary, takes the step)."""
    check(("seq", (("prim", "A", False), ("prim", "B", False))), [(X, X)] * 4, {("A",) * 4})
    check(("prim", "A", True), [()] * 3, {("A", "A", "A"), ("A", "A", S), ("A", S, S), (S, S, S)})


def test_stationary_follows_the_end_of_the_top_level_behaviour():
    """After the top-level behaviour ends the output is Stationary at every step, whatever the guards."""
    check(("for", ("prim", "A", False), 2), [()] * 4, {("A", "A", S, S)})
    check(("until", ("prim", "A", False), 0), [(F,), (T,), (F,), (X,)], {("A", S, S, S)})
    hfsm = to_hfsm(("prim", "A", False))
    assert hfsm.step(TERMINATED, StepInputs((), PERIOD)) == [Output(S, TERMINATED)]


def test_a_step_in_which_scenic_loops_forever_has_no_outcome():
    """A handler whose condition surely holds and that surely ends at once (``do A until g`` on g) is
    started again and again in the same step: Scenic never ends the step, the HFSM gives no outcome."""
    tree = ("try", ("prim", "B", False), ((0, ("until", ("prim", "A", False), 0)),))
    check(tree, [(F,), (T,)], set())
    assert reference_prefixes(tree, [(F,), (T,)]) == {(), ("B",)}
    check(tree, [(X,)], {("A",), ("B",)})


SCENIC_PRIMITIVE = """import builtins
LOG = builtins.HFSM_SEMANTICS_LOG
behavior Prim(label):
    while True:
        LOG.append((simulation().currentTime, label))
        wait
"""


def test_scenic_gives_priority_to_the_handler_written_last(tmp_path):
    """Scenic's compiler passes the handlers to runTryInterrupt last-written first ("in order from high
    priority to low, so reversed relative to the syntax"): of two enabled handlers the one written last
    runs. (The handler lists of this file and of hfsm.TryInterrupt are in runTryInterrupt's order.)"""
    source = (
        SCENIC_PRIMITIVE
        + """behavior Top():
    try:
        do Prim("C")
    interrupt when True:
        do Prim("A")
    interrupt when True:
        do Prim("B")
ego = new Object with behavior Top()
"""
    )
    assert run_scenic(source, 2, tmp_path) == ("B", "B")
    check(
        ("try", ("prim", "C", False), ((0, ("prim", "B", False)), (0, ("prim", "A", False)))), [(T,)] * 2, {("B", "B")}
    )


def test_the_translated_try_gives_priority_to_the_handler_written_last():
    """A program's try (scenario.translate) must list its handlers in Scenic's priority order, the one
    written last first: with both conditions true (the other car within 5 m, so within 10 m) Scenic runs
    TurnBehavior, the handler written last, not LaneChangeBehavior."""
    program = """model scenic.simulators.newtonian.driving_model

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=10)
    interrupt when (distance to otherCar) < 5:
        do LaneChangeBehavior(laneSectionToSwitch=self.laneSection._laneToLeft, target_speed=10)
    interrupt when (distance to otherCar) < 10:
        do TurnBehavior()

ego = new Car with behavior EgoBehavior()
otherCar = new Car on visible ego.lane, with name "otherCar"
"""
    query = compile_scenario(program)
    inputs = StepInputs((CAN_TRUE,) * len(query.guards), PERIOD)
    assert {o.label for o in query.hfsms["ego"].step(None, inputs)} == {"Turn"}


def test_for_counts_the_steps_during_which_it_is_suspended():
    """Scenic's ``do X for N steps`` ends when ``currentTime - startTime >= N``: simulation time, so the
    steps during which a handler suspends the statement count too.

    ``try: do A for 2 steps / interrupt when g: B``: A at step 0; g holds at step 1, so B; at step 2 g is
    false and B may run on (B) or end, and then the body resumes with 2 steps elapsed since it started,
    so the ``for`` ends, the body and the try end: Stationary. Not A: A ran only 1 step, but 2 passed.
    """
    tree = ("try", ("for", ("prim", "A", False), 2), ((0, ("prim", "B", True)),))
    check(tree, [(F,), (T,), (F,)], {("A", "B", "B"), ("A", "B", S)})


def test_for_in_a_later_handler_counts_the_steps_an_earlier_one_runs():
    """Handler 2 (B for 2 steps) starts at step 0; handler 1 (A for 1 step) pre-empts it at step 1; at
    step 2 handler 1 ends, handler 2 resumes, but 2 steps have passed since it started, so it ends too
    and the body (D) runs, all in step 2."""
    tree = ("try", ("prim", "D", False), ((0, ("for", ("prim", "A", False), 1)), (1, ("for", ("prim", "B", False), 2))))
    check(tree, [(F, T), (T, F), (F, F), (F, F)], {("B", "A", "D", "D")})
