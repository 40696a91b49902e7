"""The random values of a scene program as coverage sees them: unique names and declared domains.

A program's random values are its continuous variables (``Range``, ``Normal``,
``TruncatedNormal``, and the free headings scenegrep adds), its finite choices (``Options``,
``Uniform``, ``Discrete``, ``DiscreteRange``) and its random points (``new Point in R``,
default positions ...). Their labels are not unique (the default position of every object of
one class has the same label), so each gets the label followed by `` #2``, `` #3`` ... when an
earlier one has the same label: earlier in the groups' (dependency) order, which puts each
object's default position in its own group, in creation order; within a group in the order
label, line, column.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from .dependencies import Group
from .terms import Term


@dataclass(frozen=True)
class Declared:
    """A random value's unique ``name``, its ``kind`` ('range', 'options' or 'point'), its source
    line, and its declared domain: [low, high] for a range (None where an end is not a constant;
    ±inf for ``Normal``), ``size`` alternatives for a choice; a point's domain is its region,
    which coverage bins by the recovered coordinates' extent."""

    name: str
    kind: str
    line: int
    low: float | None = None
    high: float | None = None
    size: int = 0


def _key(leaf: Term) -> Any:
    return leaf.value[0] if leaf.op == "point" else leaf.value


def _order(key: Any) -> tuple:
    span = getattr(key, "span", None)
    return (key.name, getattr(span, "line", 0), getattr(span, "column", 0))


def unique_names(groups: Iterable[Group]) -> dict[Any, str]:
    """Unique display names of the random values (keyed by their RandomVariable, FiniteChoice or
    RandomPoint) of the groups' unknowns; see the module docstring."""
    keys: dict[Any, None] = {}
    for group in groups:
        for leaf in sorted(group.unknowns, key=lambda leaf: (_order(_key(leaf)), repr(leaf))):
            keys.setdefault(_key(leaf), None)
    seen: Counter[str] = Counter()
    names = {}
    for key in keys:
        seen[key.name] += 1
        names[key] = key.name if seen[key.name] == 1 else f"{key.name} #{seen[key.name]}"
    return names


def declared(groups: list[Group]) -> list[Declared]:
    """The declared random values of the groups' unknowns: variables and choices in the program's
    order (line, column), then random points (map coordinates, the least telling) in the order of
    :func:`unique_names`."""
    names = unique_names(groups)
    leaves = {_key(leaf): leaf for group in groups for leaf in group.unknowns}
    found = []
    points = [key for key in names if leaves[key].op == "point"]
    scalars = sorted((key for key in names if leaves[key].op != "point"), key=lambda key: _order(key)[1:])
    for key in scalars + points:
        name = names[key]
        leaf = leaves[key]
        line = getattr(getattr(key, "span", None), "line", 0)
        if leaf.op == "var":
            found.append(Declared(name, "range", line, _constant(key.low), _constant(key.high)))
        elif leaf.op == "choice":
            found.append(Declared(name, "options", line, size=key.size))
        else:
            found.append(Declared(name, "point", line))
    return found


def _constant(term: Term) -> float | None:
    if term.is_const and isinstance(term.value, (int, float)):
        value = float(term.value)
        return value if not math.isnan(value) else None
    return None
