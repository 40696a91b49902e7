"""ValidStep as a lazily built deterministic automaton (seed 000 Algorithm 2, the RE2 way).

A *symbol* is what one frame shows one HFSM: the value of each of its guards and
the set of its outputs the observed label admits. A DFA state is a set of HFSM
configurations (the paper's current base states, with their context); the
transition on a symbol is ValidStep: step every configuration (:meth:`Hfsm.step`)
and keep the outcomes whose output the label admits. State 0 is the empty set
(the HFSM cannot produce the observed labels: dead, absorbing) and state 1 is
the initial configuration. Transitions are computed once and memoised, so a
trace of any length costs table look-ups, vectorised in :mod:`.windows`.
"""

from __future__ import annotations

import numpy as np

from ..errors import UserError
from .hfsm import BOTH, Config, Hfsm, Output, StepInputs

DEAD = 0
INITIAL = 1
MAX_STATES = 50_000


def encode(masks: np.ndarray, guard_codes: list[np.ndarray], n_outputs: int) -> np.ndarray:
    """Per-frame symbols from output masks and the codes of the HFSM's guards (in its order)."""
    symbols = masks.astype(np.int64)
    for q, codes in enumerate(guard_codes):
        symbols = symbols | (codes.astype(np.int64) << (n_outputs + 2 * q))
    return symbols


class Automaton:
    """The lazy DFA of one HFSM for one frame period (s); see the module docstring."""

    def __init__(self, hfsm: Hfsm, n_guards: int, period: float):
        self.hfsm = hfsm
        self.outputs = hfsm.outputs()
        self.bit = {label: 1 << p for p, label in enumerate(self.outputs)}
        self.n_guards = n_guards
        self.period = period
        self.sets: list[frozenset[Config]] = [frozenset(), frozenset({None})]
        self.index: dict[frozenset[Config], int] = {s: i for i, s in enumerate(self.sets)}
        self.memo: dict[tuple[int, int], int] = {}

    def inputs(self, symbol: int) -> StepInputs:
        values = [BOTH] * self.n_guards
        code = symbol >> len(self.outputs)
        for guard in self.hfsm.guards:
            values[guard] = code & 3
            code >>= 2
        return StepInputs(tuple(values), self.period)

    def outcomes(self, state: int, symbol: int) -> list[tuple[Config, Output]]:
        """Every (configuration, outcome) of one step from the configurations of ``state``."""
        inputs = self.inputs(symbol)
        return [(c, o) for c in self.sets[state] for o in self.hfsm.step(c, inputs)]

    def next(self, state: int, symbol: int) -> int:
        key = (state, symbol)
        found = self.memo.get(key)
        if found is None:
            mask = symbol & ((1 << len(self.outputs)) - 1)
            kept = frozenset(o.config for _, o in self.outcomes(state, symbol) if mask & self.bit[o.label])
            found = self._intern(kept)
            self.memo[key] = found
        return found

    def _intern(self, configs: frozenset[Config]) -> int:
        found = self.index.get(configs)
        if found is None:
            if len(self.sets) >= MAX_STATES:
                raise UserError(f"the behaviour of {self.hfsm.obj} has too many reachable state sets to query")
            found = len(self.sets)
            self.sets.append(configs)
            self.index[configs] = found
        return found

    def table(self, symbols: np.ndarray) -> np.ndarray:
        """(states, len(symbols)) next-state table over the states reachable from INITIAL with these symbols."""
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
