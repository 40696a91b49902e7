"""The user's choice for map layers a map's format does not publish (unknown layers).

A layer a map's format publishes but this map holds no element of is *empty* (as in Scenic). A
layer the format does not publish (:attr:`RoadMap.unknown_layers`) is *unknown*: a query or
labelling rule that needs it is an error naming the layer, unless the user chose how to treat
it: ``permissive`` (the layer is everywhere: anything goes) or ``strict`` (the layer is empty).
The same choice covers the direction of sidewalks and crossings on a map that does not give it (no
centrelines): permissive takes it as any heading, strict as none (nothing oriented by it matches).
The choice counts, per layer, the decisions its assumption affected (those whose answer would
differ under the other assumption), for the report on stderr.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field

from ..errors import SourceLocation, UserError

MODES = ("permissive", "strict")
"""How an unknown layer may be treated: as everywhere, or as empty."""

OPTION = "--unknown-layers"
"""The command-line option that makes the choice (named in errors)."""


@dataclass(eq=False)
class UnknownLayers:
    """The choice (``mode`` one of :data:`MODES`, or None: an unknown layer a decision needs is an
    error) and, per layer, how many decisions the assumption affected."""

    mode: str | None = None
    decisions: Counter[str] = field(default_factory=Counter)

    def __post_init__(self) -> None:
        if self.mode is not None and self.mode not in MODES:
            raise UserError(f"{OPTION} must be one of {', '.join(MODES)} (got {self.mode!r})")

    @property
    def everywhere(self) -> bool:
        """Whether an unknown layer is taken to cover everything (else: to be empty)."""
        return self.mode == "permissive"

    def refuse(
        self, layers: Iterable[str], needed_by: str, map_name: str, location: SourceLocation | None = None
    ) -> UserError:
        """The error for a decision that needs the unknown ``layers`` without a choice."""
        names = sorted(layers)
        what = f"the {names[0]} layer" if len(names) == 1 else f"the {' and '.join(names)} layers"
        return UserError(
            f"the road map {map_name!r} does not publish {what}, which {needed_by} needs; "
            f"say how to treat unknown layers with {OPTION} {'|'.join(MODES)}",
            location,
        )

    def refuse_direction(
        self, layers: Iterable[str], needed_by: str, map_name: str, location: SourceLocation | None = None
    ) -> UserError:
        """The error for a decision that needs the direction of the elements of ``layers``
        (``sidewalk``, ``crossing``: Scenic orients them along their centrelines), which the map
        does not give, without a choice."""
        what = " and ".join(f"{layer}s" for layer in sorted(layers))
        return UserError(
            f"the road map {map_name!r} does not give the direction of its {what} (no centrelines), "
            f"which {needed_by} needs; say how to treat unknown layers with {OPTION} {'|'.join(MODES)}",
            location,
        )

    def count(self, layer: str, decisions: int) -> None:
        """Record ``decisions`` decisions whose answer the assumption about ``layer`` decided."""
        if decisions:
            self.decisions[layer] += int(decisions)

    def report(self) -> str | None:
        """The line for stderr when a choice was made (None without one)."""
        if self.mode is None:
            return None
        meaning = "everywhere" if self.everywhere else "empty"
        choice = f"{OPTION} {self.mode}: unknown map layers taken as {meaning}"
        counts = ", ".join(f"{layer} {n}" for layer, n in sorted(self.decisions.items())) or "none"
        return f"{choice}; decisions affected: {counts}"
