"""Colours shared by every view: one per canonical object kind, one per program name."""

from __future__ import annotations

from collections.abc import Iterable

from ..model.taxonomy import KINDS

KIND_COLOURS = {
    "car": "#4c78a8",
    "truck": "#2f4b7c",
    "bus": "#665191",
    "trailer": "#7a7a9c",
    "motorcycle": "#00a3a3",
    "bicycle": "#43aa8b",
    "pedestrian": "#9c6644",
    "animal": "#b08968",
    "static": "#9e9e9e",
    "other": "#bdbdbd",
}
"""Muted colours of the objects nobody picked, by kind (every kind of the taxonomy has one)."""

PROGRAM_COLOURS = ("#e63946", "#f4a261", "#d62ad0", "#2a9d8f", "#ffb703", "#8338ec", "#06d6a0", "#fb5607")
"""Bright colours of the corresponded objects, in the order their program names appear."""

MARKED_COLOUR = "#ff7f0e"
"""Colour of observations of a class a SpRE names."""


def class_colours() -> dict[str, str]:
    """The colour of every kind."""
    assert set(KIND_COLOURS) == set(KINDS)
    return dict(KIND_COLOURS)


def program_colours(names: Iterable[str]) -> dict[str, str]:
    """A colour for every program name (``ego`` first), cycling through :data:`PROGRAM_COLOURS`."""
    ordered = sorted(dict.fromkeys(names), key=lambda n: (n != "ego", n))
    return {name: PROGRAM_COLOURS[k % len(PROGRAM_COLOURS)] for k, name in enumerate(ordered)}
