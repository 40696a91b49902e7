"""Regions and vector fields of a scene program, as symbolic values over terms.

A region is where a random point may fall (``on road``), what ``X in R``
tests, and where an object must be contained. Map regions are named layers of
the :class:`~scenegrep.model.RoadMap`; the others are built from terms (the
visible sector of an object, the lane of a point) and combined by Scenic's
region operations. A field gives a heading at a point: the road direction, or a
region's preferred orientation. Their meaning over a concrete map is in
:mod:`.geometry`.

Scenic's driving-domain names map to layers as follows (``MAP_NAMES``):
``road`` is the drivable region (lanes, roads and intersections), ``lane`` the
lanes, ``intersection``, ``crossing``, ``sidewalk`` and ``curb`` (a set of
polylines) their layers, ``walkableRegion`` sidewalks and crossings.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from .terms import Term

LAYERS = ("drivable", "road", "lane", "intersection", "crossing", "sidewalk", "curb", "shoulder")
"""Map layers a region can name. ``road`` is the road polygons without intersections
(Scenic's ``network.roadRegion``); ``drivable`` is Scenic's ``road``."""

ORIENTED_LAYERS = {
    "drivable": "lanes",
    "road": "lanes",
    "lane": "lanes",
    "intersection": "lanes",
    "curb": "curb",
    "sidewalk": "sidewalk",
    "crossing": "crossing",
}
"""Layers with a preferred orientation, and the field giving it."""

ELEMENT_FIELDS = {"sidewalk": ("sidewalk",), "crossing": ("crossing",), "walkable": ("sidewalk", "crossing")}
"""Fields given by the centrelines of map elements, and their layers in Scenic's order: a point
takes the direction of the first element containing it (``VectorField.forUnionOf``)."""


class Region:
    """Base of region values."""

    def terms(self) -> Iterator[Term]:
        """The terms this region's shape depends on."""
        yield from ()

    def layers(self) -> Iterator[str]:
        """The map layers this region reads."""
        yield from ()


@dataclass(frozen=True)
class MapRegion(Region):
    """A layer of the road map (see :data:`LAYERS`)."""

    layer: str

    def layers(self) -> Iterator[str]:
        yield self.layer


@dataclass(frozen=True)
class Everywhere(Region):
    """The whole plane (Scenic's ``everywhere``, and the driving workspace)."""


@dataclass(frozen=True)
class Nowhere(Region):
    """The empty region."""


@dataclass(frozen=True)
class LaneAt(Region):
    """The lane(s) containing the point (x, y): ``obj.lane``."""

    x: Term
    y: Term

    def terms(self) -> Iterator[Term]:
        yield self.x
        yield self.y

    def layers(self) -> Iterator[str]:
        yield "lane"


@dataclass(frozen=True)
class Sector(Region):
    """A circular sector: centre, radius (m), heading of its axis and opening angle (rad).

    An angle of 2π or more is the whole disc (the visible region of a Point or of an
    OrientedPoint with the default view angle).
    """

    cx: Term
    cy: Term
    radius: Term
    heading: Term
    angle: Term

    def terms(self) -> Iterator[Term]:
        yield from (self.cx, self.cy, self.radius, self.heading, self.angle)


@dataclass(frozen=True)
class Combination(Region):
    """A region made of parts (see :class:`Intersection` and :class:`Union`)."""

    parts: tuple[Region, ...]

    def terms(self) -> Iterator[Term]:
        for part in self.parts:
            yield from part.terms()

    def layers(self) -> Iterator[str]:
        for part in self.parts:
            yield from part.layers()


@dataclass(frozen=True)
class Intersection(Combination):
    """Points in every part."""


@dataclass(frozen=True)
class Union(Combination):
    """Points in some part."""


@dataclass(frozen=True)
class Difference(Region):
    """Points of ``base`` not in ``removed``."""

    base: Region
    removed: Region

    def terms(self) -> Iterator[Term]:
        yield from self.base.terms()
        yield from self.removed.terms()

    def layers(self) -> Iterator[str]:
        yield from self.base.layers()
        yield from self.removed.layers()


WALKABLE = Union((MapRegion("sidewalk"), MapRegion("crossing")))
"""Scenic's ``network.walkableRegion`` (sidewalks, then crossings); its orientation is the
``walkable`` field."""


class Field:
    """Base of vector-field values: a heading at each point."""

    def terms(self) -> Iterator[Term]:
        yield from ()


@dataclass(frozen=True)
class MapField(Field):
    """A heading field of the map: ``lanes`` (the direction of travel of the lanes containing the
    point, Scenic's ``roadDirection`` and the orientation of road, lane and intersection regions),
    ``curb`` (the direction of the curb segment at the point), or one of :data:`ELEMENT_FIELDS`
    (the orientation of the sidewalks, the crossings, the walkable region)."""

    name: str


@dataclass(frozen=True)
class LaneDirection(Field):
    """The direction of the lane(s) containing (x, y), evaluated at the query point (``obj.lane.orientation``)."""

    x: Term
    y: Term

    def terms(self) -> Iterator[Term]:
        yield self.x
        yield self.y


def orientation_of(region: Region) -> Field | None:
    """The preferred orientation of a region, or None (Scenic: the first oriented part of an
    intersection; sectors and discs have none)."""
    if region == WALKABLE:
        return MapField("walkable")
    if isinstance(region, MapRegion):
        name = ORIENTED_LAYERS.get(region.layer)
        return None if name is None else MapField(name)
    if isinstance(region, LaneAt):
        return LaneDirection(region.x, region.y)
    if isinstance(region, (Intersection, Union)):
        for part in region.parts:
            field = orientation_of(part)
            if field is not None:
                return field
    if isinstance(region, Difference):
        return orientation_of(region.base)
    return None
