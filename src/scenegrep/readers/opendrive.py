"""OpenDRIVE road networks (``.xodr``), read through Scenic's own road network.

Scenic's :class:`scenic.domains.driving.roads.Network` parses the file (seconds
for a CARLA town); the result is converted to the data model's
:class:`~scenegrep.model.RoadMap` and cached as a Parquet map in the user cache
(keyed by the file's SHA-256 and the Scenic version), so later loads take
milliseconds and never import Scenic.

Scenic's ``.snet`` files are pickles, and unpickling runs whatever code the file names, so
this reader never lets Scenic near one: a map must be a regular file named ``*.xodr`` (a
``.snet``, a file without a suffix, a directory or a fifo named as an OpenDRIVE map is a
:class:`UserError`), and it is parsed with ``Network.fromOpenDrive``, which reads only XML
(``Network.fromFile`` would load a ``.snet`` named by the path, or found beside it).

Centrelines are Scenic's, vertex for vertex, so lane directions (the heading of the
centreline segment a point projects onto) are exactly Scenic's ``roadDirection``; where
OpenDRIVE geometry pieces overlap they double back for a few centimetres (168 vertices
in Town01), and points projecting onto those short segments get the reversed
direction there, as in Scenic.

Conversion (through the private accessors ``_successor``, ``_predecessor``, ``_laneToLeft``,
``_laneToRight``, which return None where the public ones reject): every Scenic lane is
a lane (id = Scenic uid such as ``road40_lane1``; lanes of connecting roads are
intersection lanes). Successors are the lane's
Scenic successor plus the connecting lanes of its maneuvers; predecessors are
the inverse links. A lane's left/right neighbour is that of its first lane
section having one, with same direction when both sections run the same way.
Roads, intersections (holding their maneuvers' connecting lanes), crossings,
sidewalks, shoulders, the curbs of ordinary roads and the drivable region come over
as they are in Scenic; sidewalks, crossings and shoulders keep their centrelines (which orient
them) and Scenic's order. Scenic 3.1.1's OpenDRIVE parser makes no crossings (its ``crossings = ()``), so
the crossing layer of every OpenDRIVE map is empty.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ElementTree
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError, at
from ..model import Area, Lane, LaneNeighbour, RoadMap
from . import map_cache
from .common import reading, regular_file

FORMAT = "opendrive"
UNKNOWN_LAYERS: frozenset[str] = frozenset()
"""Scenic's road network publishes every layer (crossings, sidewalks, curbs, shoulders), so an
OpenDRIVE map without, say, sidewalks has an empty sidewalk layer, as in Scenic."""
CONVERSION_VERSION = 6
"""Bumped whenever the conversion changes, so cached maps are rebuilt."""


def _neighbour(lane: Any, side: str) -> LaneNeighbour | None:
    for section in lane.sections:
        other = getattr(section, f"_laneTo{side}")
        if other is not None:
            return LaneNeighbour(other.lane.uid, bool(other.isForward == section.isForward))
    return None


def _successors(lane: Any) -> tuple[str, ...]:
    found = [lane._successor.uid] if lane._successor is not None else []
    found += [m.connectingLane.uid for m in lane.maneuvers if m.connectingLane is not None]
    return tuple(dict.fromkeys(found))


def _lanes(network: Any) -> list[Lane]:
    connecting = {road.uid for road in network.connectingRoads}
    successors = {lane.uid: _successors(lane) for lane in network.lanes}
    predecessors: dict[str, list[str]] = {lane.uid: [] for lane in network.lanes}
    for lane in network.lanes:
        if lane._predecessor is not None:
            predecessors[lane.uid].append(lane._predecessor.uid)
        for succ in successors[lane.uid]:
            predecessors.setdefault(succ, []).append(lane.uid)
    return [
        Lane(
            lane.uid,
            lane.polygon,
            np.asarray(lane.centerline.points, dtype=np.float64)[:, :2],
            road=lane.road.uid,
            is_intersection=lane.road.uid in connecting,
            successors=successors[lane.uid],
            predecessors=tuple(dict.fromkeys(predecessors[lane.uid])),
            left=_neighbour(lane, "Left"),
            right=_neighbour(lane, "Right"),
            speed_limit=lane.speedLimit,
        )
        for lane in network.lanes
    ]


def _curbs(network: Any) -> tuple[np.ndarray, ...]:
    groups = [g for road in network.roads for g in (road.forwardLanes, road.backwardLanes) if g]
    return tuple(np.asarray(g.curb.points, dtype=np.float64)[:, :2] for g in groups)


def _oriented_areas(elements: Any) -> tuple[Area, ...]:
    """Sidewalks, crossings or shoulders with their centrelines, in Scenic's order (its union's
    orientation, and its road direction on shoulders, take the first element containing a point)."""
    return tuple(
        Area(e.uid, e.polygons, centreline=np.asarray(e.centerline.points, np.float64)[:, :2]) for e in elements
    )


def convert_network(network: Any, name: str, source: str) -> RoadMap:
    """A :class:`RoadMap` from a Scenic road network."""
    intersections = tuple(
        Area(i.uid, i.polygons, tuple(dict.fromkeys(m.connectingLane.uid for m in i.maneuvers)))
        for i in network.intersections
    )
    roads = tuple(Area(r.uid, r.polygons, tuple(lane.uid for lane in r.lanes)) for r in network.roads)
    return RoadMap(
        name,
        tuple(_lanes(network)),
        roads,
        intersections,
        _oriented_areas(network.crossings),
        _oriented_areas(network.sidewalks),
        _curbs(network),
        network.drivableRegion.polygons,
        source,
        _oriented_areas(network.shoulders),
        UNKNOWN_LAYERS,
    )


def checked_xodr(path: str | Path) -> Path:
    """``path`` when it names a regular ``.xodr`` file; a one-line :class:`UserError` otherwise
    (in particular for Scenic's pickled ``.snet`` caches, which are never read)."""
    path = Path(path)
    if path.suffix.lower() != ".xodr":
        raise UserError(
            "not an OpenDRIVE map: expected a .xodr file (Scenic .snet caches are pickles and are never read)",
            at(path),
        )
    return regular_file(path, "an OpenDRIVE .xodr file")


def parse_network(path: Path) -> Any:
    """Scenic's Network parsed from an .xodr file by ``Network.fromOpenDrive`` (XML only, never
    a pickle; imports Scenic: about a second). Parse failures are :class:`UserError`\\ s."""
    path = checked_xodr(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from scenic.domains.driving.roads import Network

        with reading(
            path,
            "OpenDRIVE file",
            ElementTree.ParseError,
            ValueError,
            KeyError,
            AttributeError,
            IndexError,
            TypeError,
            RuntimeError,
        ):
            return Network.fromOpenDrive(str(path))


def cached_map_path(path: Path) -> Path:
    """Where the converted map of an .xodr file is cached."""
    return map_cache.cached_map_path(path, _cache_tag())


def _cache_tag() -> str:
    """The cache tag of a conversion: the Scenic version and :data:`CONVERSION_VERSION`."""
    return f"scenic{version('scenic')}-v{CONVERSION_VERSION}"


def read_map(path: str | Path, key: str | None = None) -> RoadMap:
    """Read an OpenDRIVE file (``key`` is unused: one map per file), through the cache
    (:mod:`.map_cache`)."""
    path = checked_xodr(path)
    return map_cache.through_cache(
        path, _cache_tag(), lambda: convert_network(parse_network(path), path.stem, str(path))
    )
