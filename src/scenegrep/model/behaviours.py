"""Primitive behaviour labels: a set of behaviour names per object per frame, with
optional confidences, aligned row-for-row with the trace's :class:`StateTable`.

Seed 000 reads a label trace's output as a *set* of feasible primitive behaviours
per object per step; a behaviour predictor's scores become such a set by
thresholding. ``member[i, k]`` says behaviour ``vocabulary[k]`` is in the set of
state row ``i``; ``confidence[i, k]`` is its score in [0, 1] (NaN when the label
carries none), or the whole matrix is ``None`` when no label has a confidence.
"""

from __future__ import annotations

from dataclasses import dataclass
from collections.abc import Iterable, Mapping

import numpy as np

from .table import RowTable


@dataclass(frozen=True, eq=False)
class BehaviourLabels(RowTable):
    """Behaviour label sets per state row; see the module docstring."""

    vocabulary: tuple[str, ...]
    member: np.ndarray
    confidence: np.ndarray | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.member.ndim != 2 or self.member.shape[1] != len(self.vocabulary):
            raise ValueError("behaviour membership must be (rows, len(vocabulary))")
        if self.confidence is not None and self.confidence.shape != self.member.shape:
            raise ValueError("behaviour confidences must have the shape of the membership matrix")

    @classmethod
    def from_sets(
        cls, sets: Iterable[Iterable[str] | Mapping[str, float | None]], vocabulary: Iterable[str] = ()
    ) -> BehaviourLabels:
        """Build from one set (or name -> confidence mapping) per state row."""
        rows = [dict(s) if isinstance(s, Mapping) else {name: None for name in s} for s in sets]
        vocab = list(dict.fromkeys(list(vocabulary) + [name for row in rows for name in row]))
        code = {name: k for k, name in enumerate(vocab)}
        member = np.zeros((len(rows), len(vocab)), dtype=bool)
        confidence = np.full(member.shape, np.nan, dtype=np.float32)
        for i, row in enumerate(rows):
            for name, score in row.items():
                member[i, code[name]] = True
                if score is not None:
                    confidence[i, code[name]] = score
        has_scores = bool(np.any(~np.isnan(confidence)))
        return cls(tuple(vocab), member, confidence if has_scores else None)

    def sets(self) -> list[frozenset[str]]:
        """The label set of every row, as Python sets (for display and tests, not hot paths)."""
        names = np.array(self.vocabulary, dtype=object)
        return [frozenset(names[row].tolist()) for row in self.member]

    def distinct_sets(self) -> tuple[list[str], np.ndarray]:
        """The distinct label sets (names joined by ',', '' for the empty set) and every row's
        code into them (an int array, one per row)."""
        names = np.array(self.vocabulary, dtype=object)
        unique, codes = np.unique(self.member, axis=0, return_inverse=True)
        return [",".join(names[row].tolist()) for row in unique], codes.reshape(-1)

    def thresholded(self, min_confidence: float) -> BehaviourLabels:
        """Keep only labels whose confidence is at least ``min_confidence`` (labels without one stay)."""
        if self.confidence is None:
            return self
        keep = self.member & ~(self.confidence < min_confidence)
        return BehaviourLabels(self.vocabulary, keep, np.where(keep, self.confidence, np.nan).astype(np.float32))
