"""The one palette of every view: the trace views (HTML page, PNG, GIF) and the charts of the
report and coverage pages (SVG, PNG) draw their colours from here alone.

Objects and image boxes take the colour of their canonical kind (an image box without an
object, its class's kind), corresponded objects the colour of their program name, behaviour
label sets a colour per set; the map, the image area and the time line have fixed colours
(:data:`SCENE_COLOURS`). The HTML page receives all of these in its data and has no palette
of its own (its style sheet only lays the page out).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from ..model.taxonomy import KINDS, kind_of

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

BEHAVIOUR_COLOURS = (
    "#4c9be8",
    "#9b5de5",
    "#f15bb5",
    "#00bbf9",
    "#00f5d4",
    "#fee440",
    "#f8961e",
    "#90be6d",
    "#577590",
    "#e76f51",
    "#8ecae6",
    "#b5838d",
)
"""Colours of the non-empty behaviour label sets, in the order of their codes (cycling)."""

NO_BEHAVIOUR_COLOUR = "#dcdde1"
"""Colour of frames where an object has no behaviour label (the empty set)."""


SCENE_COLOURS = {
    "background": ("#eef0f2", "none"),
    "timeline": ("#f0f1f3", "none"),
    "lane": ("#dfe3e8", "#c3c8cf"),
    "intersection": ("#b4bcc8", "none"),
    "crosswalk": ("#ffffff", "#b0b6bf"),
    "image": ("#20242a", "#888888"),
    "count": ("#c9ced6", "none"),
    "window": ("#e63946", "#e63946"),
}
"""(fill, edge) of the scene's and the time line's backgrounds, of the map's lanes,
intersections and crosswalks, of a camera image's area, of the time line's objects-per-frame
bars and of its match window."""

CHART_COLOURS = ("#4c78a8", "#f58518", "#54a24b", "#e45756")
"""Colours of a chart's series, in order (the first is the colour of a chart of one series)."""

GAP_COLOUR = "#e45756"
"""A coverage chart's bins that no data covers."""

UNKNOWN_COLOUR = "#bbbbbb"
"""A coverage chart's bins whose coverage is unknown (failed traces, an interrupted run)."""


def class_colours() -> dict[str, str]:
    """The colour of every kind."""
    assert set(KIND_COLOURS) == set(KINDS)
    return dict(KIND_COLOURS)


def category_colours(categories: Iterable[str]) -> list[str]:
    """The colour of each class name as a dataset spells it: its canonical kind's."""
    return [KIND_COLOURS[kind_of(category)] for category in categories]


def program_colours(names: Iterable[str]) -> dict[str, str]:
    """A colour for every program name (``ego`` first), cycling through :data:`PROGRAM_COLOURS`."""
    ordered = sorted(dict.fromkeys(names), key=lambda n: (n != "ego", n))
    return {name: PROGRAM_COLOURS[k % len(PROGRAM_COLOURS)] for k, name in enumerate(ordered)}


def behaviour_colours(sets: Sequence[str]) -> list[str]:
    """The colour of each distinct behaviour label set, indexed by its code (the order of
    ``BehaviourTable.distinct_sets``): the empty set :data:`NO_BEHAVIOUR_COLOUR`, the k-th
    non-empty set ``BEHAVIOUR_COLOURS[k % 12]``."""
    colours, k = [], 0
    for labels in sets:
        if labels:
            colours.append(BEHAVIOUR_COLOURS[k % len(BEHAVIOUR_COLOURS)])
            k += 1
        else:
            colours.append(NO_BEHAVIOUR_COLOUR)
    return colours
