"""The rows of an object array grouped by the object they hold, without a Python step per row.

A decoder's string column repeats a few string objects over many rows (one per distinct id, class
or frame name); :func:`by_object` numbers the rows by object. An object array stores a pointer to
each element, and in CPython ``id(x)`` is that pointer: :func:`addresses` reads them as integers
(what ``map(id, column)`` gives, at the cost of a copy, not of a call per row). :func:`factorize`
numbers integer keys through a table indexed by their bits when no two distinct keys fall in one
slot (the common case for the few objects of a batch), else with a sort.
"""

from __future__ import annotations

import ctypes

import numpy as np

SLOTS = 1 << 14
"""The slots of :func:`factorize`'s table (a key's slot: its bits 4 to 17; objects are 16-byte aligned)."""


def addresses(column: np.ndarray) -> np.ndarray:
    """``id()`` of every element of an object array, as int64 (the array's own pointers, copied)."""
    column = np.ascontiguousarray(column, dtype=object)
    if not len(column):
        return np.empty(0, dtype=np.int64)
    pointers = (ctypes.c_int64 * len(column)).from_address(column.ctypes.data)
    return np.frombuffer(pointers, dtype=np.int64).copy()


def factorize(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Codes of int64 ``keys`` (equal keys, equal codes; the codes 0..k-1 number the k distinct
    keys) and, per code, a row holding its key."""
    slot = (keys >> 4) & (SLOTS - 1)
    held = np.empty(SLOTS, dtype=np.int64)
    held[slot] = keys
    if np.array_equal(held[slot], keys):  # no two distinct keys in one slot
        used = np.zeros(SLOTS, dtype=bool)
        used[slot] = True
        row = np.empty(SLOTS, dtype=np.int64)
        row[slot] = np.arange(len(keys))
        return (np.cumsum(used) - 1)[slot], row[used]
    _, first, codes = np.unique(keys, return_index=True, return_inverse=True)
    return codes.ravel(), first


def by_object(column: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rows of an object array numbered by the object they hold, and one row per number."""
    return factorize(addresses(column))
