"""Sliding windows (seed 000 Algorithm 2) for every start frame at once.

Algorithm 2 restarts the HFSMs at each start frame i and runs ValidStep for m
frames: O(n·m) steps. Here each frame t is a function ``step[t]`` from DFA
states to DFA states (:mod:`.automaton`; state 0 is dead and absorbing), and
:func:`reach` computes, for every start i, how many consecutive frames the run
begun at i survives, capped at ``cap``: compositions of 2^k consecutive frames
are built by doubling (binary lifting), then each start greedily takes the
largest blocks that keep it alive. Time O(n·S·log cap) in numpy for S states;
a window of m frames starting at i is admitted iff ``reach[i] >= m``. For an
automaton with final acceptance (a temporal requirement's monitor) the state
after the m frames must also be accepting; a window whose run survives but ends
elsewhere gets reach m - 1.
"""

from __future__ import annotations

import numpy as np

from .automaton import DEAD, INITIAL, LazyDfa, OverBudget

MAX_CELLS = 1 << 26
"""At most this many DFA states x frames x doubling levels in :func:`table_reach` (256 MB of int32)."""


def reach(step: np.ndarray, initial: int, cap: int) -> tuple[np.ndarray, np.ndarray]:
    """Per start frame, the number of frames (at most ``cap``) survived from state ``initial``,
    and the state after them.

    ``step[t, s]`` is the state after frame t from state s. A row of zeros (a dead frame)
    separates independent sequences laid end to end.
    """
    n = len(step)
    levels = [step]
    while (2 << (len(levels) - 1)) <= min(cap, n):
        previous = levels[-1]
        half = 1 << (len(levels) - 1)
        levels.append(np.take_along_axis(previous[half:], previous[: len(previous) - half], axis=1))
    state = np.full(n, initial, dtype=step.dtype)
    position = np.arange(n)
    length = np.zeros(n, dtype=np.int64)
    for k in range(len(levels) - 1, -1, -1):
        block = 1 << k
        level = levels[k]
        can = np.flatnonzero((position < len(level)) & (length + block <= cap))
        after = level[position[can], state[can]]
        alive = after != DEAD
        can = can[alive]
        state[can] = after[alive]
        position[can] += block
        length[can] += block
    return length, state


def table_reach(automaton: LazyDfa, symbols: np.ndarray, cap: int) -> np.ndarray:
    """(k, n) per row of ``symbols`` (k, n) and start frame, the frames (at most ``cap``) survived
    from INITIAL, by :func:`reach` over the DFA's table, all rows at once (laid end to end with a
    dead frame between them); with final acceptance, ``cap - 1`` where the run survives ``cap``
    frames but does not end in an accepting state. Raises :class:`.automaton.OverBudget` when the DFA is over its state
    budget or the doubling tables would hold more than :data:`MAX_CELLS` states."""
    unique, inverse = np.unique(symbols, return_inverse=True)
    table = automaton.table(unique)
    k, n = symbols.shape
    if k * (n + 1) * table.shape[0] * min(cap, n).bit_length() > MAX_CELLS:
        raise OverBudget(f"the step tables of {automaton.name} would be too large")
    step = np.zeros((k, n + 1, table.shape[0]), dtype=table.dtype)
    step[:, :n] = np.transpose(table[:, inverse.reshape(k, n)], (1, 2, 0))
    length, state = reach(step.reshape(k * (n + 1), -1), INITIAL, cap)
    if automaton.final_acceptance:
        refused = (length >= cap) & ~automaton.accepting_states()[state]
        length[refused] = cap - 1
    return length.reshape(k, n + 1)[:, :n]
