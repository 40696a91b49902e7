"""Rows numbered by the object they hold (readers/ros/factorize.py): the addresses are what
``id()`` gives, and equal keys get equal codes whether the slot table or the sort numbers them."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.readers.ros.factorize import SLOTS, addresses, by_object, factorize


@given(st.lists(st.integers(0, 6), max_size=40), st.lists(st.integers(-(2**40), 2**40), min_size=1, max_size=7))
def test_equal_keys_and_only_they_share_a_code(picks, values):
    # keys 16 * SLOTS apart fall in one slot: the table refuses them and the sort numbers them
    base = np.array(values, dtype=np.int64) * 16 * SLOTS
    for pool in (base, np.arange(len(values), dtype=np.int64) * 16):
        keys = pool[np.array(picks, dtype=np.int64) % len(pool)]
        codes, first = factorize(keys)
        assert len(first) == len(set(keys.tolist())) and sorted(set(codes.tolist())) == list(range(len(first)))
        assert np.array_equal(keys[first][codes], keys)


def test_addresses_are_the_ids_of_the_elements():
    names = ["a", "b", "c" * 40, "a"]
    column = np.empty(7, dtype=object)
    column[:] = [names[k % 4] for k in range(7)]
    assert addresses(column[::2]).tolist() == [id(x) for x in column[::2]]
    codes, first = by_object(column)
    assert column[first][codes].tolist() == column.tolist()
    assert addresses(np.empty(0, dtype=object)).tolist() == []
