"""Classes a SpRE requires: names ``c`` such that every frame sequence the query reports as a
match has a frame where an object (or box) of class ``c`` is present.

A pure function over the syntax tree, used to skip traces that never hold such an object.
It is sound, not complete: it only names classes it can prove necessary. A class atom
``[:c:]`` names a class or a canonical kind (see :mod:`scenegrep.spre.space`); ``*`` and
``ego`` are never required. Reported matches are never empty (see :class:`syntax.Empty`).
"""

from __future__ import annotations

from functools import reduce

from . import syntax as s

Needs = frozenset[str] | None
"""Required class names; None stands for "impossible" (the query part cannot match anything
non-empty), the identity of intersection."""

NEVER_REQUIRED = frozenset({"*", "ego"})


def required_classes(query: s.Query) -> frozenset[str]:
    """The class names every reported match of ``query`` needs present in some frame."""
    found = _query(query)
    return frozenset() if found is None else found - NEVER_REQUIRED


def _union(a: Needs, b: Needs) -> Needs:
    return None if a is None or b is None else a | b


def _intersection(a: Needs, b: Needs) -> Needs:
    if a is None:
        return b
    return a if b is None else a & b


def nullable(query: s.Query) -> bool:
    """Whether the query matches the empty sequence."""
    match query:
        case s.Letter() | s.AnyFrame():
            return False
        case s.Empty():
            return True
        case s.Concat(items):
            return all(nullable(q) for q in items)
        case s.Alternation(options):
            return any(nullable(q) for q in options)
        case s.Repeat(item, low, _):
            return low == 0 or nullable(item)
        case s.TrackBinder(_, body):
            return nullable(body)
    raise TypeError(f"not a query node: {query!r}")


def _query(query: s.Query) -> Needs:
    """What every non-empty match of ``query`` needs."""
    match query:
        case s.Letter(formula):
            return _formula(formula)
        case s.AnyFrame():
            return frozenset()
        case s.Empty():
            return None
        case s.Concat(items):
            solid = [q for q in items if not nullable(q)]
            if solid:
                return reduce(_union, (_query(q) for q in solid))
            return reduce(_intersection, (_query(q) for q in items))
        case s.Alternation(options):
            return reduce(_intersection, (_query(q) for q in options))
        case s.Repeat(item, _, high):
            return None if high == 0 else _query(item)
        case s.TrackBinder(binding, body):
            return _union(frozenset({binding.atom.name}), _query(body))
    raise TypeError(f"not a query node: {query!r}")


def _formula(formula: s.Formula) -> frozenset[str]:
    """What a frame satisfying ``formula`` holds."""
    match formula:
        case s.Present(term) | s.NonEmpty(term):
            return _term(term)
        case s.And(left, right):
            return _formula(left) | _formula(right)
        case s.Or(left, right):
            return _formula(left) & _formula(right)
        case s.Quantifier(_, bindings, body):
            return frozenset(b.atom.name for b in bindings) | _formula(body)
        case s.Subset(left, right):
            return _term(left) | _term(right)
        case s.Relation(_, left, right):
            return _term(left) | (frozenset() if right is None else _term(right))
    return frozenset()


def _term(term: s.Term) -> frozenset[str]:
    """What a frame holds when ``term`` has a non-empty region."""
    match term:
        case s.ClassAtom(name, _):
            return frozenset({name})
        case s.Intersection(left, right):
            return _term(left) | _term(right)
        case s.Union(left, right):
            return _term(left) & _term(right)
        case s.Interior(inner) | s.Closure(inner):
            return _term(inner)
    return frozenset()
