"""What evaluating an expression or a specifier needs of the program being resolved.

:mod:`.expressions` and :mod:`.specifiers` take a :class:`Context` as their first argument ``r``
and :class:`~.resolve.Resolver` is the one that provides it, so neither imports the resolver:
imports point one way, ``resolve -> specifiers -> expressions -> context``.
"""

from __future__ import annotations

from typing import Any, Protocol

from ..errors import UserError
from ..scenic import ir
from .domain import Default
from .program import SceneProgram
from .terms import TermFactory
from .values import Instance


class Context(Protocol):
    """A program under resolution: its terms, names, objects and ``self``, and its source text."""

    f: TermFactory
    """The factory every term of the program is made by (shared terms are one object)."""
    scene: SceneProgram
    """The scene program being built: its objects and requirements."""
    scope: dict[str, Any]
    """The program's variables, by name."""
    instances: list[Instance]
    """Every object and point the program has created so far, in order."""
    self_view: Any
    """What ``self`` reads inside the specifiers of the object being built (None outside them)."""
    visible_distance: float | None
    """Random points lie within this distance (m) of the ego; None: anywhere in their region."""
    free_fields: frozenset[str]
    """Map fields whose headings are free (an unpublished layer the user chose to assume)."""

    def error(self, message: str, where: ir.Node | ir.Span) -> UserError:
        """A user error naming the program's file, line and column of ``where``."""
        ...

    def evaluate_default(self, default: Default) -> Any:
        """A class default's value."""
        ...

    def label(self, node: ir.Node) -> str:
        """How a random value made at ``node`` is named in explanations (its text and place)."""
        ...

    def local_path(self, relative: str) -> str:
        """``localPath``: a path relative to the program's folder."""
        ...

    def lookup(self, node: ir.Name) -> Any:
        """The value of a name."""
        ...
