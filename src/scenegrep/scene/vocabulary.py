"""Program objects no searched trace can correspond to, by kind.

A Scenic object corresponds only to a labeled object of one of its class's kinds
(:attr:`ProgramObject.kinds <scenegrep.scene.program.ProgramObject.kinds>`; None: any kind). When
no searched trace has an object of those kinds, the query cannot match anywhere: a silent "no
match" otherwise. Each such program object is one warning line naming its kinds and the kinds the
data has.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from ..wording import article, listed


def unknown_kinds(objects: Iterable[Any], kinds: Iterable[str]) -> list[str]:
    """One warning per program object (of ``objects``) whose kinds none of ``kinds``, the canonical
    kinds of the searched traces' objects, is."""
    have = set(kinds)
    return [
        f"no trace searched has {_kinds(o.kinds)} object for {o.class_name} {o.name!r} (kinds there: {listed(have)})"
        for o in objects
        if o.kinds is not None and not o.kinds & have
    ]


def _kinds(kinds: frozenset[str]) -> str:
    """``a car``, ``an animal``, ``a bicycle or pedestrian``."""
    text = " or ".join(sorted(kinds))
    return f"{article(text)} {text}"
