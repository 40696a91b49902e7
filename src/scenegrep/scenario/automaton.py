"""ValidStep as a lazily built deterministic automaton (seed 000 Algorithm 2, the RE2 way).

A *symbol* is what one frame shows one HFSM: the value of each of its guards and
the set of its outputs the observed label admits. A DFA state is a set of HFSM
configurations (the paper's current base states, with their context); the
transition on a symbol is ValidStep: step every configuration (:meth:`Hfsm.step`)
and keep the outcomes whose output the label admits. State 0 is the empty set
(the HFSM cannot produce the observed labels: dead, absorbing) and state 1 is
the initial configuration. Transitions are computed once and memoised, so a
trace of any length costs table look-ups, vectorised in :mod:`.windows`. The
same lazy construction (:class:`LazyDfa`) serves the monitors of temporal
requirements (:mod:`.temporal`), whose runs must also end in an accepting state.

The DFA holds at most ``budget`` states; one more raises :class:`OverBudget`, and
the caller falls back to simulating configuration sets (:mod:`.simulate`), as RE2
falls back from its DFA to its NFA. The per-configuration step
(:meth:`LazyDfa.successors`) is shared by both and memoised.
"""

from __future__ import annotations

import numpy as np

from .hfsm import BOTH, Config, Hfsm, StepInputs

DEAD = 0
INITIAL = 1
MAX_STATES = 10_000
"""The default state budget of one HFSM's DFA (building it costs about a second at most)."""


class OverBudget(Exception):
    """The DFA would need more states than its budget; simulate configuration sets instead."""


def encode(masks: np.ndarray, guard_codes: list[np.ndarray], n_outputs: int) -> np.ndarray:
    """Per-frame symbols from output masks and the codes of the HFSM's guards (in its order)."""
    symbols = masks.astype(np.int64)
    for q, codes in enumerate(guard_codes):
        symbols = symbols | (codes.astype(np.int64) << (n_outputs + 2 * q))
    return symbols


class LazyDfa:
    """The lazy subset construction over a nondeterministic step of hashable configurations, with
    at most ``budget`` states; see the module docstring. Subclasses give :meth:`step_config`
    (unmemoised), the ``initial`` configuration, the ``guards`` a symbol carries (after
    ``len(outputs)`` label bits) and, for automata whose runs must end in an accepting
    configuration (temporal requirements), :meth:`accepting`; ``name`` names it in messages."""

    name: str
    initial: Config = None
    guards: tuple[int, ...] = ()
    outputs: tuple[str, ...] = ()
    final_acceptance = False
    """False: every live configuration accepts, so a window is admitted iff its run survives m frames."""

    def __init__(self, budget: int = MAX_STATES):
        self.budget = budget
        self.over_budget = False
        self.sets: list[frozenset[Config]] = [frozenset(), frozenset({self.initial})]
        self.index: dict[frozenset[Config], int] = {s: i for i, s in enumerate(self.sets)}
        self.memo: dict[tuple[int, int], int] = {}
        self._successors: dict[tuple[Config, int], frozenset[Config]] = {}

    def step_config(self, config: Config, symbol: int) -> frozenset[Config]:
        raise NotImplementedError

    def accepting(self, config: Config) -> bool:
        """Whether a run that ends in ``config`` is accepted (only read when ``final_acceptance``)."""
        return True

    def guard_values(self, symbol: int) -> list[int]:
        """The value (CAN_TRUE | CAN_FALSE bits) of each of ``guards`` in a symbol."""
        code = symbol >> len(self.outputs)
        return [(code >> (2 * q)) & 3 for q in range(len(self.guards))]

    def successors(self, config: Config, symbol: int) -> frozenset[Config]:
        """One step of one configuration on a symbol (memoised)."""
        key = (config, symbol)
        found = self._successors.get(key)
        if found is None:
            found = self.step_config(config, symbol)
            self._successors[key] = found
        return found

    def step_set(self, configs: frozenset[Config], symbol: int) -> frozenset[Config]:
        """One step of a configuration set."""
        return frozenset().union(*(self.successors(c, symbol) for c in configs))

    def next(self, state: int, symbol: int) -> int:
        """The DFA transition; raises :class:`OverBudget` if it needs a state beyond the budget."""
        key = (state, symbol)
        found = self.memo.get(key)
        if found is None:
            found = self._intern(self.step_set(self.sets[state], symbol))
            self.memo[key] = found
        return found

    def _intern(self, configs: frozenset[Config]) -> int:
        found = self.index.get(configs)
        if found is None:
            if len(self.sets) >= self.budget:
                self.over_budget = True
                raise OverBudget(f"the DFA of {self.name} needs more than {self.budget} states")
            found = len(self.sets)
            self.sets.append(configs)
            self.index[configs] = found
        return found

    def table(self, symbols: np.ndarray) -> np.ndarray:
        """(states, len(symbols)) next-state table over the states reachable from INITIAL with these
        symbols; raises :class:`OverBudget` when they are more than the budget."""
        values = [int(s) for s in symbols]
        seen = {DEAD, INITIAL}
        queue = [INITIAL]
        while queue:
            state = queue.pop()
            for symbol in values:
                nxt = self.next(state, symbol)
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
        table = np.zeros((len(self.sets), len(values)), dtype=np.int32)
        for state in seen:
            table[state] = [self.memo[(state, s)] for s in values] if state != DEAD else 0
        return table

    def accepting_states(self) -> np.ndarray:
        """Per DFA state built so far, whether a run ending in it is accepted."""
        return np.array([any(self.accepting(c) for c in s) for s in self.sets], dtype=bool)


class Automaton(LazyDfa):
    """The lazy DFA of one HFSM for one frame period (s), with at most ``budget`` states: a symbol
    is the frame's admitted-output mask and the HFSM's guard values; a step is ValidStep."""

    def __init__(self, hfsm: Hfsm, n_guards: int, period: float, budget: int = MAX_STATES):
        self.hfsm = hfsm
        self.name = hfsm.obj
        self.guards = hfsm.guards
        self.outputs = hfsm.outputs()
        self.bit = {label: 1 << p for p, label in enumerate(self.outputs)}
        self.n_guards = n_guards
        self.period = period
        super().__init__(budget)

    def inputs(self, symbol: int) -> StepInputs:
        values = [BOTH] * self.n_guards
        for guard, value in zip(self.guards, self.guard_values(symbol)):
            values[guard] = value
        return StepInputs(tuple(values), self.period)

    def outputs_from(self, configs: frozenset[Config], symbol: int) -> set[str]:
        """Every output one step from ``configs`` can produce, before the label prunes them."""
        inputs = self.inputs(symbol)
        return {o.label for c in configs for o in self.hfsm.step(c, inputs)}

    def step_config(self, config: Config, symbol: int) -> frozenset[Config]:
        """ValidStep of one configuration: the configurations after one step whose output the
        symbol's label admits."""
        mask = symbol & ((1 << len(self.outputs)) - 1)
        outcomes = self.hfsm.step(config, self.inputs(symbol))
        return frozenset(o.config for o in outcomes if mask & self.bit[o.label])
