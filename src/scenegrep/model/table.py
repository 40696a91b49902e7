"""Columnar row tables: frozen dataclasses whose array fields are equal-length columns.

Every table of the data model (states, objects, image samples and boxes) is a
:class:`RowTable`. Fields holding a :class:`numpy.ndarray` are columns (a 2-D
array is a column of fixed-width rows); any other field (a vocabulary tuple, say)
is table-level and is carried over unchanged by :meth:`RowTable.take`.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Self

import numpy as np


def _arrays_equal(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape or a.dtype.kind != b.dtype.kind:
        return False
    if a.dtype.kind == "f":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))


@dataclass(frozen=True, eq=False)
class RowTable:
    """Base class of the columnar tables. Subclasses declare their columns as fields."""

    def __post_init__(self) -> None:
        lengths = {f.name: len(v) for f in fields(self) if isinstance(v := getattr(self, f.name), np.ndarray)}
        if len(set(lengths.values())) > 1:
            raise ValueError(f"{type(self).__name__}: columns of different lengths {lengths}")

    def __len__(self) -> int:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                return len(value)
        return 0

    def columns(self) -> dict[str, np.ndarray]:
        """The array-valued fields by name."""
        return {f.name: v for f in fields(self) if isinstance(v := getattr(self, f.name), np.ndarray)}

    def take(self, rows: np.ndarray | slice) -> Self:
        """A new table of the selected rows (an index array, a boolean mask or a slice)."""
        values: dict[str, Any] = {}
        for f in fields(self):
            value = getattr(self, f.name)
            values[f.name] = value[rows] if isinstance(value, np.ndarray) else value
        return type(self)(**values)

    def equals(self, other: object) -> bool:
        """Field-by-field equality; NaN equals NaN in float columns."""
        if type(other) is not type(self):
            return False
        for f in fields(self):
            mine, theirs = getattr(self, f.name), getattr(other, f.name)
            if isinstance(mine, np.ndarray) or isinstance(theirs, np.ndarray):
                if not (
                    isinstance(mine, np.ndarray) and isinstance(theirs, np.ndarray) and _arrays_equal(mine, theirs)
                ):
                    return False
            elif isinstance(mine, RowTable):
                if not mine.equals(theirs):
                    return False
            elif mine != theirs:
                return False
        return True


def float_column(values: Any) -> np.ndarray:
    """A float64 column from any array-like."""
    return np.ascontiguousarray(values, dtype=np.float64)


def int_column(values: Any, dtype: type = np.int32) -> np.ndarray:
    """An integer column (int32 by default) from any array-like."""
    return np.ascontiguousarray(values, dtype=dtype)


def str_column(values: Any) -> np.ndarray:
    """A column of Python strings (numpy object array)."""
    out = np.empty(len(values), dtype=object)
    out[:] = [str(v) for v in values]
    return out
