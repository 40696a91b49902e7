"""Waymo Open Motion Dataset scenarios: ``waymo.open_dataset.Scenario`` protobufs in
TFRecord files (one scenario per record, many per file), read without TensorFlow
or the waymo-open-dataset package.

The message classes are built at import time, in a private descriptor pool, from
a hand-made proto2 descriptor holding only the messages and fields read here
(field numbers of the public ``scenario.proto`` and ``map.proto``); every other
field is skipped by the parser. Enum fields are declared ``int32`` (the same wire
encoding) so that values newer than this reader are kept rather than dropped as
unknown fields of a closed proto2 enum.

Traces: one per scenario, in file order. Every entry of ``timestamps_seconds`` is a
frame (10 Hz, 91 frames in WOMD); frame times are seconds since the first. Every
track is an object (id = the track's id, class = its object type in lower case:
``vehicle``, ``pedestrian``, ``cyclist``, ``other``, ``unset``) with a state in the
frames where it is ``valid``: centre x, y, z (m), heading (yaw from +x converted to
the Scenic convention), length, width, height (m) and velocity (m/s). The ego is
the track at ``sdc_track_index``. Trace attributes: ``scenario_id``,
``time_origin_s`` (the first timestamp, s), ``current_time_index``, and the
space-separated track ids of ``objects_of_interest`` and ``tracks_to_predict``.

Road map of a scenario (the scenario's ``scenario_id`` is the map key):

- a lane per ``LaneCenter`` feature: its polyline is the centreline; successors and
  predecessors are its exit and entry lanes; the first listed left and right
  neighbours are its neighbours (the proto lists same-direction lanes only);
  ``BIKE_LANE`` lanes are of kind ``bike``; the speed limit is converted from mph.
- Waymo gives no lane outlines. A lane's polygon is its centreline buffered with flat
  caps by a half-width estimated as the median distance from its centreline points
  to the road lines and road edges named as its left and right boundaries (each
  over the centreline points the boundary segment covers), clipped to
  [:data:`MIN_HALF_WIDTH_M`, :data:`MAX_HALF_WIDTH_M`]; a lane without boundaries
  gets :data:`DEFAULT_HALF_WIDTH_M`.
- Waymo names no intersections. A lane is an intersection lane when its centreline
  crosses another lane's on the same level, away from both lanes' ends
  (:func:`scenegrep.model.lane_topology.crossing_lanes`): that finds junctions,
  driveway and parking entries, and not overpasses; lanes a traffic signal controls
  at any step are intersection lanes too (right turns often cross nothing). (The proto's hint that lane
  centres in intersections have no boundaries does not hold in real data: junction
  lanes often carry one-point boundary segments where they touch road lines.)
  Intersection areas are the connected unions of those lanes and roads the
  laterally linked groups of the others.
- crosswalks are the ``Crosswalk`` polygons and curbs the ``RoadEdge`` polylines;
  traffic signals, stop signs, speed bumps and driveways are not part of the map.
- degenerate features are left out: lanes, road lines and road edges of fewer than
  two points, crosswalks of fewer than three (links to a left-out lane stay as ids).
"""

from __future__ import annotations

from operator import attrgetter
from pathlib import Path
from typing import Any
from collections.abc import Iterator

import numpy as np
import shapely
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.message import DecodeError, Message

from ..errors import SourceLocation, UserError, at
from ..model import Area, Lane, LaneNeighbour, LabelTrace, MapSource, ObjectTable, RoadMap, StateTable, TraceSource
from ..model.geometry import heading_from_yaw
from ..model.lane_shapes import line_strings
from ..model.lane_topology import crossing_lanes, derive_intersections, derive_roads
from .tfrecord import read_records, record_location

FORMAT = "waymo-tfrecord"

UNKNOWN_LAYERS = frozenset({"sidewalk", "shoulder"})
"""Layers a WOMD Scenario does not publish (it has crosswalks and road edges, used as curbs)."""
MIN_HALF_WIDTH_M = 1.0
MAX_HALF_WIDTH_M = 3.0
DEFAULT_HALF_WIDTH_M = 1.8
"""Bounds of a lane's estimated half-width (m), and the half-width of a lane without boundaries."""

MPH_TO_MPS = 0.44704

_PACKAGE = "waymo.open_dataset"
_ONEOF = "feature_data"

_SCHEMA: dict[str, tuple[tuple[str, int, str], ...]] = {
    "MapPoint": (("x", 1, "double"), ("y", 2, "double"), ("z", 3, "double")),
    "ObjectState": (
        ("center_x", 2, "double"),
        ("center_y", 3, "double"),
        ("center_z", 4, "double"),
        ("length", 5, "float"),
        ("width", 6, "float"),
        ("height", 7, "float"),
        ("heading", 8, "float"),
        ("velocity_x", 9, "float"),
        ("velocity_y", 10, "float"),
        ("valid", 11, "bool"),
    ),
    "Track": (("id", 1, "int32"), ("object_type", 2, "int32"), ("states", 3, "repeated ObjectState")),
    "TrafficSignalLaneState": (("lane", 1, "int64"), ("state", 2, "int32"), ("stop_point", 3, "MapPoint")),
    "DynamicMapState": (("lane_states", 1, "repeated TrafficSignalLaneState"),),
    "BoundarySegment": (
        ("lane_start_index", 1, "int32"),
        ("lane_end_index", 2, "int32"),
        ("boundary_feature_id", 3, "int64"),
        ("boundary_type", 4, "int32"),
    ),
    "LaneNeighbor": (
        ("feature_id", 1, "int64"),
        ("self_start_index", 2, "int32"),
        ("self_end_index", 3, "int32"),
        ("neighbor_start_index", 4, "int32"),
        ("neighbor_end_index", 5, "int32"),
        ("boundaries", 6, "repeated BoundarySegment"),
    ),
    "LaneCenter": (
        ("speed_limit_mph", 1, "double"),
        ("type", 2, "int32"),
        ("interpolating", 3, "bool"),
        ("polyline", 8, "repeated MapPoint"),
        ("entry_lanes", 9, "packed int64"),
        ("exit_lanes", 10, "packed int64"),
        ("left_neighbors", 11, "repeated LaneNeighbor"),
        ("right_neighbors", 12, "repeated LaneNeighbor"),
        ("left_boundaries", 13, "repeated BoundarySegment"),
        ("right_boundaries", 14, "repeated BoundarySegment"),
    ),
    "RoadLine": (("type", 1, "int32"), ("polyline", 2, "repeated MapPoint")),
    "RoadEdge": (("type", 1, "int32"), ("polyline", 2, "repeated MapPoint")),
    "StopSign": (("lane", 1, "repeated int64"), ("position", 2, "MapPoint")),
    "Crosswalk": (("polygon", 1, "repeated MapPoint"),),
    "SpeedBump": (("polygon", 1, "repeated MapPoint"),),
    "Driveway": (("polygon", 1, "repeated MapPoint"),),
    "MapFeature": (
        ("id", 1, "int64"),
        ("lane", 3, "oneof LaneCenter"),
        ("road_line", 4, "oneof RoadLine"),
        ("road_edge", 5, "oneof RoadEdge"),
        ("stop_sign", 7, "oneof StopSign"),
        ("crosswalk", 8, "oneof Crosswalk"),
        ("speed_bump", 9, "oneof SpeedBump"),
        ("driveway", 10, "oneof Driveway"),
    ),
    "RequiredPrediction": (("track_index", 1, "int32"), ("difficulty", 2, "int32")),
    "Scenario": (
        ("scenario_id", 5, "string"),
        ("timestamps_seconds", 1, "repeated double"),
        ("current_time_index", 10, "int32"),
        ("tracks", 2, "repeated Track"),
        ("dynamic_map_states", 7, "repeated DynamicMapState"),
        ("map_features", 8, "repeated MapFeature"),
        ("sdc_track_index", 6, "int32"),
        ("objects_of_interest", 4, "repeated int32"),
        ("tracks_to_predict", 11, "repeated RequiredPrediction"),
    ),
    "ScenarioKey": (("scenario_id", 5, "string"),),
}
"""Message name -> fields (name, number, type). A type is a scalar type or a message name,
optionally after ``repeated``, ``packed`` (a packed repeated scalar) or ``oneof`` (a member of
the message's oneof :data:`_ONEOF`). ``ScenarioKey`` is a Scenario read for its id alone."""

_FIELD = descriptor_pb2.FieldDescriptorProto
_SCALARS = {
    "double": _FIELD.TYPE_DOUBLE,
    "float": _FIELD.TYPE_FLOAT,
    "int32": _FIELD.TYPE_INT32,
    "int64": _FIELD.TYPE_INT64,
    "bool": _FIELD.TYPE_BOOL,
    "string": _FIELD.TYPE_STRING,
}

_CATEGORIES = {0: "unset", 1: "vehicle", 2: "pedestrian", 3: "cyclist", 4: "other"}
"""Track.ObjectType values -> object class; other values are ``other``."""

_BIKE_LANE = 3
"""LaneCenter.LaneType of bike lanes."""

_STATE_FIELDS = (
    "center_x",
    "center_y",
    "center_z",
    "heading",
    "length",
    "width",
    "height",
    "velocity_x",
    "velocity_y",
    "valid",
)
_state_values = attrgetter(*_STATE_FIELDS)
_point_xy = attrgetter("x", "y")


def _add_field(message: descriptor_pb2.DescriptorProto, name: str, number: int, spec: str) -> None:
    """Declare a field of ``message`` from its :data:`_SCHEMA` entry."""
    qualifier, _, type_name = spec.rpartition(" ")
    field = message.field.add(name=name, number=number)
    field.label = _FIELD.LABEL_REPEATED if qualifier in ("repeated", "packed") else _FIELD.LABEL_OPTIONAL
    if type_name in _SCALARS:
        field.type = _SCALARS[type_name]
    else:
        field.type = _FIELD.TYPE_MESSAGE
        field.type_name = f".{_PACKAGE}.{type_name}"
    if qualifier == "packed":
        field.options.packed = True
    if qualifier == "oneof":
        if not message.oneof_decl:
            message.oneof_decl.add(name=_ONEOF)
        field.oneof_index = 0


def _message_classes() -> dict[str, type[Message]]:
    """The message classes of :data:`_SCHEMA`, built in a private descriptor pool."""
    file = descriptor_pb2.FileDescriptorProto(name="scenegrep/waymo_scenario.proto", package=_PACKAGE, syntax="proto2")
    for name, fields in _SCHEMA.items():
        message = file.message_type.add(name=name)
        for spec in fields:
            _add_field(message, *spec)
    pool = descriptor_pool.DescriptorPool()
    pool.Add(file)
    return {name: message_factory.GetMessageClass(pool.FindMessageTypeByName(f"{_PACKAGE}.{name}")) for name in _SCHEMA}


MESSAGES = _message_classes()
"""The message classes by name (``MESSAGES["Scenario"]`` and the messages it holds)."""


# ---------------------------------------------------------------------- records
def _parse(name: str, data: bytes, path: str | Path, number: int) -> Any:
    """Record ``number`` of ``path`` parsed as a Scenario (``name`` = ``Scenario`` or ``ScenarioKey``)."""
    message = MESSAGES[name]()
    try:
        message.ParseFromString(data)
    except DecodeError as exc:
        raise UserError(f"not a Waymo Scenario record: {exc}", record_location(path, number)) from None
    if not message.scenario_id:
        raise UserError("not a Waymo Scenario record: it has no scenario_id", record_location(path, number))
    return message


def read_scenarios(path: str | Path) -> Iterator[tuple[int, Any]]:
    """(record number from 1, ``Scenario`` message) of every record of a file, in file order."""
    for number, data in enumerate(read_records(path), start=1):
        yield number, _parse("Scenario", data, path, number)


# ---------------------------------------------------------------------- traces
def _track_ids(indices: Any, ids: list[str], what: str, where: SourceLocation) -> list[str]:
    """The ids of the tracks at ``indices``; UserError for an index out of range."""
    bad = [i for i in indices if not 0 <= i < len(ids)]
    if bad:
        raise UserError(f"{what} {bad[0]} is out of range: the scenario has {len(ids)} tracks", where)
    return [ids[i] for i in indices]


def _state_grid(scenario: Any, n_frames: int, where: SourceLocation) -> np.ndarray:
    """The values of :data:`_STATE_FIELDS` as a (frames, tracks, fields) float array."""
    for track in scenario.tracks:
        if len(track.states) != n_frames:
            raise UserError(f"track {track.id} has {len(track.states)} states for {n_frames} timestamps", where)
    grid = np.array([list(map(_state_values, track.states)) for track in scenario.tracks], dtype=np.float64)
    return grid.reshape(len(scenario.tracks), n_frames, len(_STATE_FIELDS)).transpose(1, 0, 2)


def _states(scenario: Any, n_frames: int, where: SourceLocation) -> StateTable:
    """The valid states of every track, in (frame, track) order."""
    grid = _state_grid(scenario, n_frames, where)
    frame, track = np.nonzero(grid[..., _STATE_FIELDS.index("valid")])
    col = dict(zip(_STATE_FIELDS, grid[frame, track].T))
    return StateTable.build(
        frame,
        track,
        col["center_x"],
        col["center_y"],
        heading_from_yaw(col["heading"]),
        z=col["center_z"],
        length=col["length"],
        width=col["width"],
        height=col["height"],
        vx=col["velocity_x"],
        vy=col["velocity_y"],
    )


def _attributes(scenario: Any, time_origin_s: float, predicted: list[str]) -> dict[str, str | int | float]:
    """The trace attributes of a scenario; ``predicted`` are the ids of its tracks to predict."""
    return {
        "dataset": "waymo-open-motion",
        "scenario_id": scenario.scenario_id,
        "time_origin_s": time_origin_s,
        "current_time_index": int(scenario.current_time_index),
        "objects_of_interest": " ".join(str(i) for i in scenario.objects_of_interest),
        "tracks_to_predict": " ".join(predicted),
    }


def _trace(scenario: Any, path: str | Path, number: int) -> LabelTrace:
    """The label trace of one Scenario message (record ``number`` of ``path``)."""
    where = record_location(path, number)
    sid = scenario.scenario_id
    times = np.asarray(scenario.timestamps_seconds, dtype=np.float64)
    if len(times) == 0:
        raise UserError(f"scenario {sid} has no timestamps", where)
    ids = [str(track.id) for track in scenario.tracks]
    if len(set(ids)) != len(ids):
        raise UserError(f"scenario {sid} has several tracks with the same id", where)
    objects = ObjectTable.build(ids, [_CATEGORIES.get(track.object_type, "other") for track in scenario.tracks])
    ego = None
    if scenario.HasField("sdc_track_index"):
        ego = _track_ids([scenario.sdc_track_index], ids, "sdc_track_index", where)[0]
    predicted = _track_ids([p.track_index for p in scenario.tracks_to_predict], ids, "tracks_to_predict index", where)
    return LabelTrace.build(
        sid,
        np.arange(len(times)),
        times - times[0],
        objects,
        _states(scenario, len(times), where),
        ego=ego,
        attributes=_attributes(scenario, float(times[0]), predicted),
        source=TraceSource(str(path), FORMAT),
        map_source=MapSource(str(path), FORMAT, key=sid),
    )


def read_traces(path: str | Path) -> Iterator[LabelTrace]:
    """One trace per Scenario record of a Waymo TFRecord file, in file order."""
    for number, scenario in read_scenarios(path):
        yield _trace(scenario, path, number)


# ---------------------------------------------------------------------- maps
def _xy(points: Any) -> np.ndarray:
    """The x, y of repeated MapPoints as a (k, 2) array (m)."""
    return np.array(list(map(_point_xy, points)), dtype=np.float64).reshape(-1, 2)


def _shapes(by_kind: dict[str, list[Any]], kind: str, attribute: str, min_points: int) -> dict[int, np.ndarray]:
    """Feature id -> x, y (k, 2) of the ``attribute`` points of every ``kind`` feature having
    at least ``min_points`` points (``by_kind``: the map features grouped by kind)."""
    shapes = {f.id: _xy(getattr(getattr(f, kind), attribute)) for f in by_kind.get(kind, [])}
    return {i: xy for i, xy in shapes.items() if len(xy) >= min_points}


def _half_width(lane: Any, centreline: np.ndarray, boundaries: dict[int, shapely.LineString]) -> float:
    """A lane's half-width (m): see the module docstring."""
    distances = [
        shapely.distance(
            shapely.points(centreline[s.lane_start_index : s.lane_end_index + 1]), boundaries[s.boundary_feature_id]
        )
        for s in (*lane.left_boundaries, *lane.right_boundaries)
        if s.boundary_feature_id in boundaries
    ]
    values = np.concatenate(distances) if distances else np.zeros(0)
    if not values.size:
        return DEFAULT_HALF_WIDTH_M
    return float(np.clip(np.median(values), MIN_HALF_WIDTH_M, MAX_HALF_WIDTH_M))


def _neighbour(neighbors: Any) -> LaneNeighbour | None:
    """The first listed neighbour lane (always same-direction in Waymo maps)."""
    return LaneNeighbour(str(neighbors[0].feature_id), True) if neighbors else None


def _lanes(by_kind: dict[str, list[Any]], boundaries: dict[int, shapely.LineString], signalled: set[int]) -> list[Lane]:
    """The lanes of the LaneCenter map features with at least two points (``signalled``: the ids
    of lanes controlled by a traffic signal)."""
    centrelines = _shapes(by_kind, "lane", "polyline", 2)
    features = [f for f in by_kind.get("lane", []) if f.id in centrelines]
    half_widths = [_half_width(f.lane, centrelines[f.id], boundaries) for f in features]
    polygons = shapely.buffer(line_strings([centrelines[f.id] for f in features]), half_widths, cap_style="flat")
    crossing = crossing_lanes([np.c_[centrelines[f.id], [p.z for p in f.lane.polyline]] for f in features])
    return [
        Lane(
            str(f.id),
            polygon,
            centrelines[f.id],
            is_intersection=bool(flag) or f.id in signalled,
            successors=tuple(str(i) for i in f.lane.exit_lanes),
            predecessors=tuple(str(i) for i in f.lane.entry_lanes),
            left=_neighbour(f.lane.left_neighbors),
            right=_neighbour(f.lane.right_neighbors),
            kind="bike" if f.lane.type == _BIKE_LANE else "vehicle",
            speed_limit=f.lane.speed_limit_mph * MPH_TO_MPS if f.lane.speed_limit_mph > 0 else None,
        )
        for f, polygon, flag in zip(features, polygons, crossing)
    ]


def _road_map(scenario: Any, path: str | Path) -> RoadMap:
    """The road map of one Scenario message."""
    by_kind: dict[str, list[Any]] = {}
    for feature in scenario.map_features:
        by_kind.setdefault(feature.WhichOneof(_ONEOF) or "", []).append(feature)
    edges = _shapes(by_kind, "road_edge", "polyline", 2)
    named = edges | _shapes(by_kind, "road_line", "polyline", 2)
    signalled = {state.lane for step in scenario.dynamic_map_states for state in step.lane_states}
    lanes = _lanes(by_kind, dict(zip(named, line_strings(list(named.values())))), signalled)
    crosswalks = tuple(
        Area(str(i), shapely.make_valid(shapely.Polygon(xy)))
        for i, xy in _shapes(by_kind, "crosswalk", "polygon", 3).items()
    )
    return RoadMap(
        scenario.scenario_id,
        tuple(lanes),
        derive_roads(lanes),
        derive_intersections(lanes),
        crosswalks,
        curbs=tuple(edges.values()),
        source=str(path),
        unknown_layers=UNKNOWN_LAYERS,
    )


def read_map(path: str | Path, key: str | None = None) -> RoadMap:
    """The road map of the scenario whose ``scenario_id`` is ``key`` (the first scenario of
    the file when None); UserError when the file holds no such scenario."""
    for number, data in enumerate(read_records(path), start=1):
        if key is None or _parse("ScenarioKey", data, path, number).scenario_id == key:
            return _road_map(_parse("Scenario", data, path, number), path)
    raise UserError("holds no scenario" if key is None else f"holds no scenario {key!r}", at(path))
