"""Growing columns (readers/ros/columns.py): rows written in steps across the switch from an
ordinary array to a map and across its growth read back as written, and the finished column is
exactly as long as asked."""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.readers.ros import columns
from scenegrep.readers.ros.columns import Column


@pytest.mark.parametrize("dtype", [np.int32, np.float64])
def test_column_keeps_every_row_across_growth(dtype, monkeypatch):
    monkeypatch.setattr(columns, "SMALL", 4096)  # (maps from 4 kB on: growth across many pages, quickly)
    rng = np.random.default_rng(3)
    steps = rng.integers(0, 700, size=40)
    expected = (rng.normal(size=int(steps.sum())) * 1000).astype(dtype)
    column, start = Column(dtype, capacity=3), 0
    for step in steps.tolist():
        column.rows(start, start + step)[:] = expected[start : start + step]
        start += step
    assert column._memory is not None  # (it did switch to a map)
    out = column.array(start)
    assert out.dtype == dtype and out.flags.writeable
    np.testing.assert_array_equal(out, expected)


def test_short_and_empty_columns_are_ordinary_arrays():
    column = Column(np.float64)
    column.rows(0, 5)[:] = np.arange(5.0)
    np.testing.assert_array_equal(column.array(5), np.arange(5.0))
    assert column._memory is None
    assert len(Column(np.int32).array(0)) == 0
