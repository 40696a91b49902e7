"""Agreement of derived labels with known running behaviours (e.g. a Scenic simulation's).

For every observation, the *truth* is one primitive behaviour (the label of a simulated trace)
and the *labelled* side is a label set. The truth is *recovered* when the set holds a label that
stands for it (:data:`~.rules.SCENIC_LABELS`, extended by the ``aliases`` given: ``LaneChange``
is recovered by LaneChangeLeft or LaneChangeRight); it is *top* when, in addition, the most
confident label is one of those.
:class:`Agreement` accumulates, per true behaviour, the observations, the recovered and top
counts, how often each label was in the set (the confusion table) and, for the observations not
recovered, the sets given instead (the disagreements, by kind).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from ..model import LabelTrace
from .rules import SCENIC_LABELS


@dataclass
class TruthCounts:
    """Counts for one true behaviour."""

    observations: int = 0
    recovered: int = 0
    top: int = 0
    set_size: int = 0
    in_set: Counter = field(default_factory=Counter)
    missed_as: Counter = field(default_factory=Counter)


@dataclass
class Agreement:
    """Per true behaviour counts over the traces :meth:`add`-ed so far."""

    truths: dict[str, TruthCounts] = field(default_factory=dict)
    aliases: dict[str, tuple[str, ...]] = field(default_factory=dict)

    def add(self, truth: LabelTrace, labelled: LabelTrace) -> None:
        """Compare ``labelled`` (the same observations, derived label sets) with ``truth`` (one
        label per observation)."""
        if truth.behaviours is None or labelled.behaviours is None or len(truth.states) != len(labelled.states):
            raise ValueError("both traces need behaviour labels for the same observations")
        true_names = np.array(truth.behaviours.vocabulary, dtype=object)[np.argmax(truth.behaviours.member, axis=1)]
        labels = labelled.behaviours
        vocabulary = np.array(labels.vocabulary, dtype=object)
        confidence = np.nan_to_num(labels.confidence, nan=-1.0) if labels.confidence is not None else labels.member
        best = vocabulary[np.argmax(confidence, axis=1)]
        for name in np.unique(true_names).tolist():
            rows = true_names == name
            accepted = np.isin(vocabulary, {**SCENIC_LABELS, **self.aliases}.get(name, (name,)))
            member = labels.member[rows]
            recovered = member[:, accepted].any(axis=1)
            counts = self.truths.setdefault(name, TruthCounts())
            counts.observations += int(rows.sum())
            counts.recovered += int(recovered.sum())
            counts.top += int((recovered & np.isin(best[rows], vocabulary[accepted])).sum())
            counts.set_size += int(member.sum())
            counts.in_set.update(dict(zip(labels.vocabulary, member.sum(axis=0).tolist())))
            for row in member[~recovered]:
                counts.missed_as[" ".join(vocabulary[row].tolist())] += 1

    def recovered_share(self, name: str) -> float:
        """Share of the observations of true behaviour ``name`` that were recovered."""
        counts = self.truths[name]
        return counts.recovered / counts.observations

    def table(self) -> str:
        """The agreement and confusion tables, then the disagreements by kind, as text."""
        labels = sorted({label for c in self.truths.values() for label, n in c.in_set.items() if n})
        lines = [f"{'running behaviour':18} {'obs':>7} {'recovered':>9} {'top':>6} {'set':>5}   in the set (% of obs)"]
        lines.append(f"{'':18} {'':>7} {'':>9} {'':>6} {'':>5}   " + " ".join(f"{label[:10]:>10}" for label in labels))
        for name, c in sorted(self.truths.items(), key=lambda item: -item[1].observations):
            shares = " ".join(f"{100.0 * c.in_set[label] / c.observations:10.1f}" for label in labels)
            lines.append(
                f"{name:18} {c.observations:7d} {100.0 * c.recovered / c.observations:8.1f}% "
                f"{100.0 * c.top / c.observations:5.1f}% {c.set_size / c.observations:5.2f}   {shares}"
            )
        lines.append("disagreements (running behaviour: label set given instead x observations)")
        for name, c in sorted(self.truths.items()):
            for labels_given, n in c.missed_as.most_common(5):
                lines.append(f"  {name}: {{{labels_given}}} x {n}")
        return "\n".join(lines)
