"""Values the resolver computes while reading a program: terms, vectors, instances, delayed values.

A scalar is a :class:`~.terms.Term`; a vector is a :class:`Vec` of two terms;
regions and fields are :mod:`.regions` values. An :class:`Instance` is the result
of ``new``: for scene objects (Object and subclasses) its position, heading and
size seen from *outside* the object are the observed label values (seed 003's
conditioning), while its other properties are the terms that define them.
A :class:`Delayed` value needs the object being built (``self``), as Scenic's
``DelayedArgument``: ``10 deg relative to roadDirection`` is a heading only once
the position it is evaluated at is known.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..scenic import ir
from .domain import ClassSpec
from .terms import Term, TermFactory
from ..wording import article


@dataclass(frozen=True)
class Vec:
    """A 2-D vector of two scalar terms (metres in the map frame)."""

    x: Term
    y: Term


@dataclass(frozen=True)
class Delayed:
    """A value computed from the object under construction: ``compute(self_view)``."""

    compute: Callable[[Any], Any]
    description: str


class SelfView:
    """``self`` while an instance is being built: :meth:`get` returns a property (see :mod:`.specifiers`)."""

    def get(self, prop: str) -> Any:
        raise NotImplementedError


@dataclass(frozen=True)
class Namespace:
    """A name holding attributes: ``network``, ``globalParameters``."""

    name: str
    attributes: dict[str, Any]


@dataclass(eq=False)
class Instance:
    """The result of ``new Class ...``.

    ``defining`` holds each property's value as the program defines it; ``observed`` (scene
    objects only) the label leaves of its features. :meth:`get` is what other code sees.
    """

    name: str
    spec: ClassSpec
    span: ir.Span
    defining: dict[str, Any] = field(default_factory=dict)
    observed: dict[str, Any] = field(default_factory=dict)

    @property
    def is_object(self) -> bool:
        return self.spec.is_object

    def get(self, prop: str) -> Any:
        """The property as seen from outside: observed for features of scene objects, else defined."""
        if prop in self.observed:
            return self.observed[prop]
        return self.defining[prop]


def observed_view(factory: TermFactory, name: str) -> dict[str, Any]:
    """The observed leaves of scene object ``name``: position, heading, orientation, width, length,
    the dynamic properties speed (m/s), velocity (m/s, map frame) and angularSpeed (rad/s), and
    scenegrep's extension acceleration (m/s², map frame; see :data:`.domain.DERIVED_PROPERTIES`)."""
    heading = factory.observed(name, "heading")
    return {
        "position": Vec(factory.observed(name, "x"), factory.observed(name, "y")),
        "heading": heading,
        "orientation": heading,
        "width": factory.observed(name, "width"),
        "length": factory.observed(name, "length"),
        "speed": factory.observed(name, "speed"),
        "velocity": Vec(factory.observed(name, "vx"), factory.observed(name, "vy")),
        "angularSpeed": factory.observed(name, "angularSpeed"),
        "acceleration": Vec(factory.observed(name, "ax"), factory.observed(name, "ay")),
    }


def type_name(value: Any) -> str:
    """A user-facing name of a value's type, for error messages."""
    if isinstance(value, Term):
        return {"num": "a number", "bool": "a boolean", "str": "a string", "none": "None"}[value.kind]
    if isinstance(value, Vec):
        return "a vector"
    if isinstance(value, Instance):
        return f"an object ({value.spec.name})" if value.is_object else f"{article(value.spec.name)} {value.spec.name}"
    if isinstance(value, Delayed):
        return "a value that depends on the object being created"
    if isinstance(value, tuple):
        return "a sequence"
    name = type(value).__name__.lower()
    return f"{article(name)} {name}"
