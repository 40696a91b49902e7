"""Sliding windows without DFA states: the fallback when an HFSM's lazy DFA is over its budget.

RE2 falls back from its DFA to an NFA simulation; here the NFA is the HFSM's configuration step
(:meth:`.automaton.LazyDfa.successors`). Per frame, every configuration some run can be in
carries the set of start frames whose run holds it, as one integer bit set: block r (``cap`` bits)
belongs to row r of the symbols, and bit d of a block to the run that started d frames ago. A
frame shifts every set by one bit (runs older than ``cap`` frames leave), adds the new starts to
the initial configuration, and moves each set along the successors of the symbol of each of its
rows. A start's run is alive while some configuration carries its bit, and runs never revive,
so its reach is the age of its bit at the last frame it is seen. With final acceptance (a
temporal requirement's monitor), a run that survives ``cap`` frames must end in an accepting
configuration, else its reach is ``cap - 1``.

Time O(n · C · F) bit-set operations of k·cap bits for n frames, C configurations live at a
frame and F distinct symbols at a frame over k rows; memory O(C · k · cap) bits. Linear in the
trace; the frames are stepped in Python (the rows and starts of a frame are handled at once),
which is acceptable for a fallback.
"""

from __future__ import annotations

import numpy as np

from .automaton import LazyDfa
from .hfsm import Config


def simulate_reach(automaton: LazyDfa, symbols: np.ndarray, cap: int) -> np.ndarray:
    """(k, n) frames survived, at most ``cap``, from the initial configuration at each start frame
    of each row of ``symbols`` (k, n): what :func:`.windows.table_reach` computes with the DFA's table."""
    k, n = symbols.shape
    lengths = np.zeros((k, n), dtype=np.int64)
    width = max(1, min(cap, n))
    blocks = [((1 << width) - 1) << (r * width) for r in range(k)]
    starts = sum(1 << (r * width) for r in range(k))
    keep = ((1 << (k * width)) - 1) & ~starts
    oldest = sum(1 << (r * width + width - 1) for r in range(k))
    refused = np.zeros((k, n), dtype=bool)
    carried: dict[Config, int] = {}
    initial = automaton.initial
    for t in range(n):
        carried = {c: bits << 1 & keep for c, bits in carried.items()}
        carried[initial] = carried.get(initial, 0) | starts
        carried = _step(automaton, carried, _row_sets(symbols[:, t], blocks))
        alive = accepted = 0
        for config, bits in carried.items():
            alive |= bits
            if automaton.final_acceptance and automaton.accepting(config):
                accepted |= bits
        _record(lengths, alive, t, k, width)
        if automaton.final_acceptance and width == cap and t >= cap - 1:
            ended = alive & oldest & ~accepted
            refused[[r for r in range(k) if ended >> (r * width + width - 1) & 1], t - cap + 1] = True
    lengths[refused] = cap - 1
    return lengths


def _row_sets(column: np.ndarray, blocks: list[int]) -> list[tuple[int, int]]:
    """(symbol, bit mask of the blocks of the rows showing it) for each distinct symbol of a frame."""
    unique, inverse = np.unique(column, return_inverse=True)
    masks = [0] * len(unique)
    for row, u in enumerate(inverse.tolist()):
        masks[u] |= blocks[row]
    return list(zip(unique.tolist(), masks))


def _step(automaton: LazyDfa, carried: dict[Config, int], rows: list[tuple[int, int]]) -> dict[Config, int]:
    """One frame: each configuration's start set moves to its successors under its rows' symbols."""
    after: dict[Config, int] = {}
    for config, bits in carried.items():
        for symbol, mask in rows:
            part = bits & mask
            if part:
                for successor in automaton.successors(config, symbol):
                    after[successor] = after.get(successor, 0) | part
    return {c: bits for c, bits in after.items() if bits}


def _record(lengths: np.ndarray, alive: int, t: int, k: int, width: int) -> None:
    """The runs alive after frame t have survived (age + 1) frames; later frames overwrite earlier."""
    raw = np.frombuffer(alive.to_bytes((k * width + 7) // 8, "little"), dtype=np.uint8)
    bits = np.unpackbits(raw, bitorder="little")[: k * width].reshape(k, width)
    rows, ages = np.nonzero(bits)
    lengths[rows, t - ages] = ages + 1
