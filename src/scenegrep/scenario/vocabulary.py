"""Primitive behaviours and the dataset labels that stand for them (:file:`vocabulary.toml`).

A behaviour the program does not define (Scenic's library behaviours such as
``FollowLaneBehavior``) is a primitive: an HFSM base state whose output is its name
without the ``Behavior`` suffix. Datasets name behaviours their own way (``LC``,
``lane_change``, ``LaneChangeLeft``), so the vocabulary maps each primitive to the set
of labels that count as it, and says whether it can end by itself.

Scenic's rule stays the default: an object without a behaviour (or whose behaviour has ended)
stands still, so it outputs :data:`STATIONARY` and its label set must hold ``Stationary``. A
primitive marked ``any`` (the shipped one is ``AnyBehavior``, primitive name ``Any``)
admits every label set, also an empty one: it is how a query says an object's behaviour does
not matter.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import UserError, at

DEFAULT_VOCABULARY = Path(__file__).with_name("vocabulary.toml")
STATIONARY = "Stationary"
"""The output of an object without a behaviour (and of one whose behaviour has ended)."""


def primitive_name(behaviour: str) -> str:
    """A behaviour's primitive name: ``FollowLaneBehavior`` -> ``FollowLane``."""
    return behaviour.removesuffix("Behavior") or behaviour


@dataclass(frozen=True)
class Primitive:
    """A primitive behaviour: its name, the labels standing for it, whether it can end by itself,
    and whether it admits every label set (``admits_any``: then ``labels`` is just its name)."""

    name: str
    labels: frozenset[str]
    ends: bool
    admits_any: bool = False


@dataclass(frozen=True)
class Vocabulary:
    """Primitive name -> :class:`Primitive`. A program may call only the primitives listed; a
    primitive the program defines itself (a ``while True:`` body) and is not listed stands for its
    own name and never ends (see :mod:`.translate`)."""

    entries: dict[str, Primitive]
    source: str = str(DEFAULT_VOCABULARY)

    def primitive(self, name: str) -> Primitive:
        return self.entries.get(name) or Primitive(name, frozenset({name}), ends=True)

    def merged(self, other: Vocabulary) -> Vocabulary:
        """This vocabulary with ``other``'s entries replacing its own."""
        return Vocabulary({**self.entries, **other.entries}, other.source)


def _entry(name: str, value: Any, source: str) -> Primitive:
    if not isinstance(value, dict) or set(value) - {"labels", "ends", "any"}:
        raise UserError(f"[{name}] must have only the keys 'labels', 'ends' and 'any'", at(source))
    labels = value.get("labels", [])
    if not isinstance(labels, list) or not all(isinstance(label, str) for label in labels):
        raise UserError(f"[{name}] labels must be a list of strings", at(source))
    ends, admits_any = value.get("ends", True), value.get("any", False)
    for key, flag in (("ends", ends), ("any", admits_any)):
        if not isinstance(flag, bool):
            raise UserError(f"[{name}] {key} must be true or false", at(source))
    if admits_any and labels:
        raise UserError(f"[{name}] admits any label (any = true), so it takes no labels", at(source))
    return Primitive(name, frozenset(labels) | {name}, ends, admits_any)


def read_vocabulary(path: str | Path) -> Vocabulary:
    """Read a vocabulary file (the layout of :file:`vocabulary.toml`)."""
    source = str(path)
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise UserError("no such vocabulary file", at(source)) from None
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"cannot read the vocabulary: {error}", at(source)) from None
    except tomllib.TOMLDecodeError as error:
        raise UserError(f"not a TOML vocabulary: {error}", at(source)) from None
    return Vocabulary({name: _entry(name, value, source) for name, value in data.items()}, source)


def load_vocabulary(path: str | Path | None = None) -> Vocabulary:
    """The shipped vocabulary, with the entries of a user's file (if given) replacing its own."""
    default = read_vocabulary(DEFAULT_VOCABULARY)
    return default if path is None else default.merged(read_vocabulary(path))
