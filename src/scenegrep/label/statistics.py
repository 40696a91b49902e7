"""Per-class statistics of behaviour labels: how often each behaviour is in an object's set.

A :class:`LabelStatistics` accumulates over any number of labelled traces; counts are per
dataset class (the trace's own class names), in observations (object x frame).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import LabelTrace
from ..wording import counted


@dataclass
class ClassCounts:
    """Counts of one class: objects, observations, total set size, observations per behaviour."""

    objects: int = 0
    observations: int = 0
    set_size: int = 0
    behaviours: dict[str, int] = field(default_factory=dict)


@dataclass
class LabelStatistics:
    """Counts per class over the labelled traces :meth:`add`-ed so far."""

    classes: dict[str, ClassCounts] = field(default_factory=dict)
    traces: int = 0

    def add(self, trace: LabelTrace) -> None:
        """Count the behaviour labels of ``trace`` (which must have some)."""
        labels = trace.behaviours
        if labels is None:
            raise ValueError("the trace has no behaviour labels")
        self.traces += 1
        category = trace.objects.category[trace.states.object]
        for name in np.unique(category).tolist():
            rows = category == name
            counts = self.classes.setdefault(name, ClassCounts())
            counts.objects += len(np.unique(trace.states.object[rows]))
            counts.observations += int(rows.sum())
            per_behaviour = labels.member[rows].sum(axis=0)
            counts.set_size += int(per_behaviour.sum())
            for behaviour, count in zip(labels.vocabulary, per_behaviour.tolist()):
                if count:
                    counts.behaviours[behaviour] = counts.behaviours.get(behaviour, 0) + count

    def table(self) -> str:
        """A text table: one line per class (most observed first), each behaviour's share of
        the class's observations in percent and the mean label-set size."""
        lines = [f"{counted(self.traces, 'trace')}; per class: objects, observations, mean set size, % of observations"]
        for name, c in sorted(self.classes.items(), key=lambda item: -item[1].observations):
            shares = "  ".join(
                f"{b} {100.0 * n / c.observations:.1f}" for b, n in sorted(c.behaviours.items(), key=lambda i: -i[1])
            )
            lines.append(
                f"  {name}: {counted(c.objects, 'object')}, {c.observations} obs, "
                f"{c.set_size / c.observations:.2f}  {shares}"
            )
        return "\n".join(lines)

    def as_dict(self) -> dict:
        """The counts as plain data (for ``--json``)."""
        return {
            "traces": self.traces,
            "classes": {
                name: {
                    "objects": c.objects,
                    "observations": c.observations,
                    "mean_set_size": c.set_size / c.observations,
                    "behaviours": dict(sorted(c.behaviours.items())),
                }
                for name, c in self.classes.items()
            },
        }
