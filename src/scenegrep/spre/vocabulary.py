"""What a SpRE names that the searched data lacks: class names and image channels.

A class atom ``[:c:]`` holds for an object or box whose class is ``c`` or (not in STREM's
compatibility mode) whose canonical kind is ``c`` (:mod:`scenegrep.spre.space`); ``*`` and ``ego``
always exist. A name that no searched trace has never holds, so the query matches only where the
atom is not needed, most often nowhere: a typo (``[:cra:]``) would otherwise be a silent "no
match". The same for an image channel (``--channel``) that no searched trace has. Each such name is
one warning line naming it and the names the data has.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from ..wording import listed
from . import syntax as s
from .requirements import NEVER_REQUIRED

if TYPE_CHECKING:
    from .search import CompiledQuery


def class_names(query: CompiledQuery) -> frozenset[str]:
    """Every class name the query's class atoms name (``*`` and ``ego`` excepted)."""
    names = {node.name for node in query.tree.walk() if isinstance(node, s.ClassAtom)}
    return frozenset(names - NEVER_REQUIRED)


def unknown_classes(query: CompiledQuery, classes: Iterable[tuple[str, str]]) -> list[str]:
    """One warning per class name of ``query`` that none of ``classes``, the (class, kind) pairs
    of the searched traces' objects or boxes, has."""
    pairs = set(classes)
    categories = {category for category, _ in pairs}
    names = categories if query.compat else categories | {kind for _, kind in pairs}
    return [
        f"no trace searched has class {name!r} (classes there: {listed(categories)})"
        for name in sorted(class_names(query) - names)
    ]


def unknown_channels(channels: Iterable[str] | None, present: Iterable[str]) -> list[str]:
    """One warning per image channel asked for (``channels``; None: all) that none of the searched
    traces has (``present``)."""
    have = set(present)
    return [
        f"no trace searched has image channel {name!r} (channels there: {listed(have)})"
        for name in sorted(set(channels or ()) - have)
    ]
