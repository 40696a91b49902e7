"""The objects (tracks) of a label trace: stable id, dataset class, free attributes."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .table import RowTable, str_column
from .taxonomy import kind_of


@dataclass(frozen=True, eq=False)
class ObjectTable(RowTable):
    """One row per object: ``id`` (unique string), ``category`` (the dataset's class name)
    and ``attributes`` (a dict per object of free attributes such as colour)."""

    id: np.ndarray
    category: np.ndarray
    attributes: np.ndarray

    def __post_init__(self) -> None:
        super().__post_init__()
        unique, counts = np.unique(self.id.astype(str), return_counts=True)
        if len(unique) != len(self.id):
            raise ValueError(f"object ids must be unique: {str(unique[np.argmax(counts > 1)])!r} is given twice")

    @classmethod
    def build(cls, ids, categories, attributes: list[dict[str, Any]] | None = None) -> ObjectTable:
        """Make a table from sequences of ids and class names (attributes default to empty)."""
        attrs = np.empty(len(ids), dtype=object)
        attrs[:] = [dict(a) for a in attributes] if attributes is not None else [{} for _ in ids]
        return cls(id=str_column(ids), category=str_column(categories), attributes=attrs)

    def kinds(self) -> np.ndarray:
        """Canonical kind of every object (see :mod:`scenegrep.model.taxonomy`)."""
        return str_column([kind_of(c) for c in self.category])

    def row_of(self) -> dict[str, int]:
        """Map from object id to row."""
        return {oid: i for i, oid in enumerate(self.id.tolist())}
