"""Sliding windows (seed 000 Algorithm 2) for every start frame at once.

Algorithm 2 restarts the HFSMs at each start frame i and runs ValidStep for m
frames: O(n·m) steps. Here each frame t is a function ``step[t]`` from DFA
states to DFA states (:mod:`.automaton`; state 0 is dead and absorbing), and
:func:`reach` computes, for every start i, how many consecutive frames the run
begun at i survives, capped at ``cap``: compositions of 2^k consecutive frames
are built by doubling (binary lifting), then each start greedily takes the
largest blocks that keep it alive. Time O(n·S·log cap) in numpy for S states;
a window of m frames starting at i is admitted iff ``reach[i] >= m``.
"""

from __future__ import annotations

import numpy as np

from .automaton import DEAD


def reach(step: np.ndarray, initial: int, cap: int) -> np.ndarray:
    """Per start frame, the number of frames (at most ``cap``) survived from state ``initial``.

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
    return length
