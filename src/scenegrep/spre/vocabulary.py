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
from dataclasses import dataclass, field

import numpy as np

from ..model import LabelTrace
from ..model.taxonomy import kind_of
from ..wording import listed
from . import syntax as s
from .requirements import NEVER_REQUIRED


def class_names(tree: s.Query) -> frozenset[str]:
    """Every class name the class atoms of a query's syntax tree name (``*`` and ``ego`` excepted)."""
    names = {node.name for node in tree.walk() if isinstance(node, s.ClassAtom)}
    return frozenset(names - NEVER_REQUIRED)


def unknown_classes(tree: s.Query, compat: bool, classes: Iterable[tuple[str, str]]) -> list[str]:
    """One warning per class name of a query (its syntax ``tree``; ``compat``: STREM's mode, where
    a class atom names a class only, not a kind) that none of ``classes``, the (class, kind)
    pairs of the searched traces' objects or boxes, has."""
    pairs = set(classes)
    categories = {category for category, _ in pairs}
    names = categories if compat else categories | {kind for _, kind in pairs}
    return [
        f"no trace searched has class {name!r} (classes there: {listed(categories)})"
        for name in sorted(class_names(tree) - names)
    ]


def unknown_channels(channels: Iterable[str] | None, present: Iterable[str]) -> list[str]:
    """One warning per image channel asked for (``channels``; None: all) that none of the searched
    traces has (``present``)."""
    have = set(present)
    return [
        f"no trace searched has image channel {name!r} (channels there: {listed(have)})"
        for name in sorted(set(channels or ()) - have)
    ]


@dataclass
class SeenNames:
    """The class names and image channels of the frames searched so far: ``classes`` of the boxes
    (image space) or objects (top-down) searched, ``channels`` of the image samples (None: no frame
    searched had images), and how many ``frames``."""

    classes: set[str] = field(default_factory=set)
    channels: set[str] | None = None
    frames: int = 0

    def add(self, trace: LabelTrace, space: str) -> None:
        """Add the frames of ``trace``, searched in ``space`` (``image`` or ``topdown``)."""
        images = trace.images
        if space == "image" and images is not None:
            self.classes.update(images.boxes.classes[code] for code in np.unique(images.boxes.category))
        else:
            self.classes.update(trace.objects.category.astype(str).tolist())
        if images is not None:
            self.channels = (self.channels or set()) | set(images.samples.channels)
        self.frames += trace.n_frames

    def warnings(self, tree: s.Query, compat: bool, channels: Iterable[str] | None) -> list[str]:
        """The warnings for the class names of a query (``tree``, ``compat`` as in
        :func:`unknown_classes`) and the image ``channels`` asked for (None: all) that the frames
        searched lack (channels only when some frame had images)."""
        found = unknown_classes(tree, compat, [(name, kind_of(name)) for name in self.classes])
        if channels and self.channels is not None:
            found += unknown_channels(channels, self.channels)
        return found
