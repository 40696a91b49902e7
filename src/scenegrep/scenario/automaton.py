"""ValidStep as a lazily built deterministic automaton (seed 000 Algorithm 2, the RE2 way).

A *symbol* is what one frame shows one HFSM: the value of each of its guards and
the set of its outputs the observed label admits. A DFA state is a set of HFSM
configurations (the paper's current base states, with their context); the
transition on a symbol is ValidStep: step every configuration (:meth:`Hfsm.step`)
and keep the outcomes whose output the label admits. State 0 is the empty set
(the HFSM cannot produce the observed labels: dead, absorbing) and state 1 is
the initial configuration. Transitions are computed once and memoised, so a
trace of any length costs table look-ups, vectorised in :mod:`.windows`.

The DFA holds at most ``budget`` states; one more raises :class:`OverBudget`, and
the caller falls back to simulating configuration sets (:mod:`.simulate`), as RE2
falls back from its DFA to its NFA. The per-configuration step
(:meth:`Automaton.successors`) is shared by both and memoised.
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


class Automaton:
    """The lazy DFA of one HFSM for one frame period (s), with at most ``budget`` states; see the
    module docstring."""

    def __init__(self, hfsm: Hfsm, n_guards: int, period: float, budget: int = MAX_STATES):
        self.hfsm = hfsm
        self.outputs = hfsm.outputs()
        self.bit = {label: 1 << p for p, label in enumerate(self.outputs)}
        self.n_guards = n_guards
        self.period = period
        self.budget = budget
        self.over_budget = False
        self.sets: list[frozenset[Config]] = [frozenset(), frozenset({None})]
        self.index: dict[frozenset[Config], int] = {s: i for i, s in enumerate(self.sets)}
        self.memo: dict[tuple[int, int], int] = {}
        self._successors: dict[tuple[Config, int], frozenset[Config]] = {}

    def inputs(self, symbol: int) -> StepInputs:
        values = [BOTH] * self.n_guards
        code = symbol >> len(self.outputs)
        for guard in self.hfsm.guards:
            values[guard] = code & 3
            code >>= 2
        return StepInputs(tuple(values), self.period)

    def outputs_from(self, configs: frozenset[Config], symbol: int) -> set[str]:
        """Every output one step from ``configs`` can produce, before the label prunes them."""
        inputs = self.inputs(symbol)
        return {o.label for c in configs for o in self.hfsm.step(c, inputs)}

    def successors(self, config: Config, symbol: int) -> frozenset[Config]:
        """ValidStep of one configuration: the configurations after one step whose output the
        symbol's label admits (memoised)."""
        key = (config, symbol)
        found = self._successors.get(key)
        if found is None:
            mask = symbol & ((1 << len(self.outputs)) - 1)
            outcomes = self.hfsm.step(config, self.inputs(symbol))
            found = frozenset(o.config for o in outcomes if mask & self.bit[o.label])
            self._successors[key] = found
        return found

    def step_set(self, configs: frozenset[Config], symbol: int) -> frozenset[Config]:
        """ValidStep of a configuration set."""
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
                raise OverBudget(f"the DFA of {self.hfsm.obj} needs more than {self.budget} states")
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
