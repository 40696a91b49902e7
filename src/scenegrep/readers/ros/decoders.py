"""Schema-specialised decoders: a batch of CDR messages of one type into :class:`Boxes` or
:class:`Transforms`.

Each decoder names the fields it needs; :func:`scenegrep.readers.ros.cdr.decode` reads just
those, for the whole batch at once, from the message definition the bag carries (so any
field order or added field of a message version is read right). Supported types (by
``pkg/Type``; ``pkg/msg/Type`` is the same):

- ``autoware_perception_msgs/TrackedObjects``, ``autoware_auto_perception_msgs/TrackedObjects``:
  UUID, most probable classification, pose, twist (the object's own frame), shape;
- ``autoware_perception_msgs/DetectedObjects`` (and the ``autoware_auto`` name): as above,
  without ids (each detection gets its own id ``<stamp ns>:<rank>``) and with the twist only
  where ``has_twist`` is set;
- ``vision_msgs/Detection3DArray``: the box (centre pose, size), the most probable hypothesis's
  ``class_id`` as the class, ``id`` (the tracking id; ``<stamp ns>:<rank>`` where empty), each
  detection's own header where it has one (frame id not empty, stamp not zero);
- ``vision_msgs/Detection2DArray``: image boxes (centre, size, rotation ``theta``), the most
  probable hypothesis's class and score; one camera channel per header frame id (the topic when
  empty); the image size is not in the message (unknown);
- ``foxglove.SceneUpdate`` in JSON or protobuf (:mod:`.foxglove`): cube entities;
- ``tf2_msgs/TFMessage`` (``/tf``, ``/tf_static``) and ``nav_msgs/Odometry`` (a link from its
  ``header.frame_id`` to its ``child_frame_id``, with the twist's linear velocity).

Shapes: a bounding box gives length, width, height (its dimensions x, y, z); a cylinder its
diameter as length and width; a polygon only its height (length and width unknown, NaN).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from .cdr import Level
from .cdr_batch import CdrBatch
from .cdr_layout import Layout
from .cdr_walk import Program, Unsupported, program
from . import _cdr_copy
from .factorize import by_object
from .foxglove import SCENE_UPDATE, decode_scene_updates
from .messages import Boxes, Coded, ImageBoxes, RawMessage, Transforms
from .msgdef import DefinitionError, Field, normalise, parse_schema

AUTOWARE_LABELS = (
    "UNKNOWN",
    "CAR",
    "TRUCK",
    "BUS",
    "TRAILER",
    "MOTORCYCLE",
    "BICYCLE",
    "PEDESTRIAN",
    "ANIMAL",
    "HAZARD",
    "OVER_DRIVABLE",
    "UNDER_DRIVABLE",
)
"""Autoware's ``ObjectClassification`` labels by value; a value past them reads as UNKNOWN."""
_LABELS = np.array(AUTOWARE_LABELS, dtype=object)

_POSE = "kinematics.pose_with_covariance.pose."
_TWIST = "kinematics.twist_with_covariance.twist.linear."
_XYZ = ("x", "y", "z")


@lru_cache(maxsize=64)
def types_of(schema_name: str, schema_data: bytes) -> dict[str, tuple[Field, ...]]:
    """The parsed definitions of a schema (cached: a bag has a few schemas, read many times)."""
    return parse_schema(schema_name, schema_data.decode("utf-8", "replace"))


def _stamp(fields: dict[str, np.ndarray], prefix: str = "header.stamp.") -> np.ndarray:
    return fields[prefix + "sec"].astype(np.int64) * 1_000_000_000 + fields[prefix + "nanosec"].astype(np.int64)


def _frames(names: np.ndarray) -> np.ndarray:
    """Frame ids without their leading slashes, each distinct string object stripped once."""
    codes, first = by_object(names)
    stripped = np.empty(len(first), dtype=object)
    stripped[:] = [str(n).lstrip("/") for n in names[first]]
    return stripped[codes]


def _ordered(level: Level) -> np.ndarray | slice:
    """The rows of a level in message order (by parent, then position in the sequence): all of
    them as they are (a slice, no copy) when they are in that order already (a batch of one
    layout is decoded in it), else a sort."""
    parent, rank = np.diff(level.parent), np.diff(level.rank)
    if ((parent > 0) | ((parent == 0) & (rank > 0))).all():
        return slice(None)
    return np.lexsort((level.rank, level.parent))


def _block(columns: list[np.ndarray]) -> np.ndarray | None:
    """The float64 columns as one (n, k) view when they lie side by side in one array (the
    fields of one block of a layout's copy, :mod:`.cdr_layout`), else None."""
    first = columns[0]
    if first.dtype != np.float64 or first.ndim != 1 or first.strides[0] < 8 * len(columns):
        return None
    start = first.__array_interface__["data"][0]
    for j, column in enumerate(columns):
        if (
            column.dtype != np.float64
            or column.shape != first.shape
            or column.strides != first.strides
            or column.base is None
            or column.base is not first.base
            or column.__array_interface__["data"][0] != start + 8 * j
        ):
            return None
    return np.lib.stride_tricks.as_strided(first, (len(first), len(columns)), (first.strides[0], 8), writeable=False)


def _vector(fields: dict[str, np.ndarray], prefix: str, names: Sequence[str], rows: np.ndarray | slice) -> np.ndarray:
    """The fields ``prefix + name`` of ``rows`` as the float64 columns of one (n, len(names)) array:
    a read-only view when they lie side by side in one array and ``rows`` is a slice."""
    block = _block([fields[prefix + n] for n in names])
    if block is not None:
        return block[rows]
    columns = [fields[prefix + n][rows] for n in names]
    out = np.empty((len(columns[0]), len(names)))
    for j, column in enumerate(columns):
        out[:, j] = column
    return out


def _best(level: Level | None, score: str, n_items: int) -> np.ndarray:
    """Per parent item (0..n_items-1), the row of ``level`` with the highest ``score`` (the first
    of equal ones; NaN lowest), -1 for a parent without rows. Rows in message order with as many
    per item (one layout) and no NaN: one argmax, else one sort."""
    best = np.full(n_items, -1, dtype=np.int64)
    if level is None or not len(level.parent):
        return best
    values = level.fields[score]
    values = values if values.dtype.kind == "f" else values.astype(np.float64)
    per = len(values) // n_items
    if (
        per * n_items == len(values)
        and all(np.array_equal(level.parent[j::per], _count(n_items)) for j in range(per))
        and all((level.rank[j::per] == j).all() for j in range(per))
        and not np.isnan(values).any()
    ):  # (the values compared as they are: a float32 orders as its float64; columns of the
        # (n_items, per) rows compared one at a time: numpy loops slowly along a short axis)
        if per == 1:
            return _count(n_items)
        return _argmax_rows(values.reshape(n_items, per)) + _count(n_items) * per
    values = values.astype(np.float64)
    order = np.lexsort((level.rank, -values, level.parent))
    parent = level.parent[order]
    first = np.r_[True, parent[1:] != parent[:-1]]
    best[parent[first]] = order[first]
    return best


_COUNT = np.arange(0)


def _count(n: int) -> np.ndarray:
    """0, 1, ..., n-1 (int64; a read-only view of one kept array, grown as needed)."""
    global _COUNT
    if len(_COUNT) < n:
        _COUNT = np.arange(max(n, 2 * len(_COUNT)), dtype=np.int64)
        _COUNT.flags.writeable = False
    return _COUNT[:n]


def _argmax_rows(values: np.ndarray) -> np.ndarray:
    """Per row of (n, per) values without NaN, the column of its first largest value (a pass per
    column when there are few: numpy's argmax along a short axis costs a call per row)."""
    if values.shape[1] > 8:
        return np.argmax(values, axis=1)
    best, top = np.zeros(len(values), dtype=np.int64), values[:, 0]
    for j in range(1, values.shape[1]):
        better = values[:, j] > top
        best[better], top = j, np.where(better, values[:, j], top)
    return best


def _best_class(levels: dict[str, Level], n_objects: int) -> np.ndarray:
    """The most probable Autoware label of every object (decode order; UNKNOWN without a
    classification or past the known labels)."""
    classes = levels.get("objects.classification")
    best = _best(classes, "probability", n_objects)
    found = best >= 0
    if found.all() and len(best):  # every object has a classification
        label = classes.fields["label"][best]
    else:
        label = np.zeros(n_objects, dtype=np.int64)
        if found.any():  # (a level of no rows has no fields)
            label[found] = classes.fields["label"][best[found]]
    return np.where(label < len(AUTOWARE_LABELS), label, 0).astype(np.int64)


def _shape_size(fields: dict[str, np.ndarray], rows: np.ndarray) -> np.ndarray:
    size = _vector(fields, "shape.dimensions.", _XYZ, rows)
    kind = fields["shape.type"][rows]
    if (kind == 0).all():  # boxes: their dimensions as they are
        return size
    size = size.copy()
    size[kind == 1, 1] = size[kind == 1, 0]
    size[kind == 2, :2] = np.nan
    size[kind > 2] = np.nan
    return size


_UUID_TEXTS: dict[bytes, str] = {}
"""Canonical texts of the UUIDs seen (kept across batches; emptied past :data:`_UUIDS_KEPT`)."""
_UUIDS_KEPT = 1 << 16


def _uuid_text(raw: np.ndarray) -> Coded:
    """Canonical UUID strings of (n, 16) bytes, as codes into the distinct ones in order of first
    appearance (numbered in C by the 16 bytes, :func:`._cdr_copy.codes16`; each text formatted
    once, and kept for the next batches)."""
    raw = np.ascontiguousarray(raw, dtype=np.uint8)
    codes, first = np.empty(len(raw), np.int64), np.empty(len(raw), np.int64)
    k = _cdr_copy.codes16(raw, codes, first)
    if len(_UUID_TEXTS) > _UUIDS_KEPT:
        _UUID_TEXTS.clear()
    texts = []
    for value in raw[first[:k]]:
        key = value.tobytes()
        text = _UUID_TEXTS.get(key)
        if text is None:
            h = key.hex()
            text = _UUID_TEXTS[key] = f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:]}"
        texts.append(text)
    names = np.empty(k, dtype=object)
    names[:] = texts
    return Coded(codes, names)


def _autoware(tracked: bool) -> tuple[frozenset[str], Callable[[dict[str, Level]], Boxes]]:
    wanted = {"header.stamp.sec", "header.stamp.nanosec", "header.frame_id", "objects.shape.type"}
    wanted |= {f"objects.{_POSE}position.{a}" for a in _XYZ}
    wanted |= {f"objects.{_POSE}orientation.{a}" for a in "xyzw"}
    wanted |= {f"objects.{_TWIST}{a}" for a in _XYZ}
    wanted |= {f"objects.shape.dimensions.{a}" for a in _XYZ}
    wanted |= {"objects.classification.label", "objects.classification.probability"}
    wanted |= {"objects.object_id.uuid"} if tracked else {"objects.kinematics.has_twist"}

    def boxes(levels: dict[str, Level]) -> Boxes:
        top, objects = levels[""], levels.get("objects")
        stamps, frames = _stamp(top.fields), _frames(top.fields["header.frame_id"])
        if objects is None or not len(objects.parent):
            return _no_boxes(stamps)
        rows = _ordered(objects)
        f = objects.fields
        message = objects.parent[rows]
        label = _best_class(levels, len(objects.parent))[rows]
        velocity = _vector(f, _TWIST, _XYZ, rows)
        if tracked:
            ids = _uuid_text(f["object_id.uuid"][rows])
        else:
            velocity = np.where(f["kinematics.has_twist"][rows, None] == 0, np.nan, velocity)
            ids = np.array([f"{s}:{r}" for s, r in zip(stamps[message], objects.rank[rows])], dtype=object)
        return Boxes(
            message,
            stamps[message],
            Coded(message, frames),
            ids,
            Coded(label, _LABELS),
            _vector(f, _POSE + "position.", _XYZ, rows),
            _vector(f, _POSE + "orientation.", "xyzw", rows),
            _shape_size(f, rows),
            velocity,
            stamps,
        )

    return frozenset(wanted), boxes


def _no_boxes(stamps: np.ndarray) -> Boxes:
    empty, text, vectors = np.empty(0, np.int64), np.empty(0, dtype=object), np.empty((0, 3))
    return Boxes(empty, empty, text, text, text, vectors, np.empty((0, 4)), vectors, vectors, stamps)


def _vision3d() -> tuple[frozenset[str], Callable[[dict[str, Level]], Boxes]]:
    stamp = ("header.stamp.sec", "header.stamp.nanosec", "header.frame_id")
    wanted = {*stamp, *(f"detections.{n}" for n in stamp), "detections.id"}
    wanted |= {f"detections.bbox.center.position.{a}" for a in _XYZ}
    wanted |= {f"detections.bbox.center.orientation.{a}" for a in "xyzw"}
    wanted |= {f"detections.bbox.size.{a}" for a in _XYZ}
    wanted |= {"detections.results.hypothesis.class_id", "detections.results.hypothesis.score"}

    def boxes(levels: dict[str, Level]) -> Boxes:
        top, found = levels[""], levels.get("detections")
        stamps, frames = _stamp(top.fields), _frames(top.fields["header.frame_id"])
        if found is None or not len(found.parent):
            return _no_boxes(stamps)
        rows = _ordered(found)
        f = found.fields
        message = found.parent[rows]
        own_stamp, own_frame = _stamp(f)[rows], _frames(f["header.frame_id"][rows])
        row_stamp = np.where(own_stamp > 0, own_stamp, stamps[message])
        row_frame = np.where(own_frame != "", own_frame, frames[message])
        results = levels.get("detections.results")
        best = _best(results, "hypothesis.score", len(found.parent))[rows]
        category = np.full(len(found.parent), "unknown", dtype=object)
        if (best >= 0).any():  # (a level of no rows has no fields)
            category[best >= 0] = results.fields["hypothesis.class_id"][best[best >= 0]]
        given = f["id"][rows]
        ids = np.array(
            [i if i else f"{s}:{r}" for i, s, r in zip(given, stamps[message], found.rank[rows])], dtype=object
        )
        return Boxes(
            message,
            row_stamp,
            row_frame,
            ids,
            category,
            _vector(f, "bbox.center.position.", _XYZ, rows),
            _vector(f, "bbox.center.orientation.", "xyzw", rows),
            _vector(f, "bbox.size.", _XYZ, rows),
            np.full((len(found.parent), 3), np.nan),
            stamps,
        )

    return frozenset(wanted), boxes


def _vision2d(topic: str) -> tuple[frozenset[str], Callable[[dict[str, Level]], ImageBoxes]]:
    centre = "detections.bbox.center."
    wanted = {"header.stamp.sec", "header.stamp.nanosec", "header.frame_id", "detections.bbox.size_x"}
    wanted |= {"detections.bbox.size_y", f"{centre}theta", *(f"{centre}position.{a}" for a in "xy")}
    wanted |= {f"{centre}{a}" for a in "xy"}  # vision_msgs 3 (geometry_msgs/Pose2D centre)
    wanted |= {"detections.results.hypothesis.class_id", "detections.results.hypothesis.score"}

    def boxes(levels: dict[str, Level]) -> ImageBoxes:
        top, found = levels[""], levels.get("detections")
        stamps, frames = _stamp(top.fields), _frames(top.fields["header.frame_id"])
        channels = np.where(frames != "", frames, topic)
        if found is None or not len(found.parent):
            empty = np.empty(0)
            return ImageBoxes(np.empty(0, np.int64), np.empty(0, dtype=object), *[empty] * 6, stamps, channels)
        rows = _ordered(found)
        f = found.fields
        position = "bbox.center.position." if "bbox.center.position.x" in f else "bbox.center."
        results = levels.get("detections.results")
        best = _best(results, "hypothesis.score", len(found.parent))[rows]
        category = np.full(len(found.parent), "unknown", dtype=object)
        score = np.full(len(found.parent), np.nan)
        if (best >= 0).any():  # (a level of no rows has no fields)
            category[best >= 0] = results.fields["hypothesis.class_id"][best[best >= 0]]
            score[best >= 0] = results.fields["hypothesis.score"][best[best >= 0]]
        column = lambda name: f[name][rows].astype(np.float64)  # noqa: E731
        return ImageBoxes(
            found.parent[rows],
            category,
            score,
            column(position + "x"),
            column(position + "y"),
            column("bbox.size_x"),
            column("bbox.size_y"),
            column("bbox.center.theta"),
            stamps,
            channels,
        )

    return frozenset(wanted), boxes


def _tf() -> tuple[frozenset[str], Callable[[dict[str, Level]], Transforms]]:
    prefix = "transforms."
    wanted = {prefix + n for n in ("header.stamp.sec", "header.stamp.nanosec", "header.frame_id", "child_frame_id")}
    wanted |= {f"{prefix}transform.translation.{a}" for a in _XYZ} | {f"{prefix}transform.rotation.{a}" for a in "xyzw"}

    def links(levels: dict[str, Level]) -> Transforms:
        level = levels.get("transforms")
        if level is None or not len(level.parent):
            return _no_links()
        rows = _ordered(level)
        f = level.fields
        return Transforms(
            level.parent[rows],
            _stamp(f)[rows],
            _frames(f["header.frame_id"][rows]),
            _frames(f["child_frame_id"][rows]),
            _vector(f, "transform.translation.", _XYZ, rows),
            _vector(f, "transform.rotation.", "xyzw", rows),
        )

    return frozenset(wanted), links


def _odometry() -> tuple[frozenset[str], Callable[[dict[str, Level]], Transforms]]:
    wanted = {"header.stamp.sec", "header.stamp.nanosec", "header.frame_id", "child_frame_id"}
    wanted |= {f"pose.pose.position.{a}" for a in _XYZ} | {f"pose.pose.orientation.{a}" for a in "xyzw"}
    wanted |= {f"twist.twist.linear.{a}" for a in _XYZ}

    def links(levels: dict[str, Level]) -> Transforms:
        f = levels[""].fields
        rows = np.arange(len(levels[""].parent))
        return Transforms(
            rows,
            _stamp(f),
            _frames(f["header.frame_id"]),
            _frames(f["child_frame_id"]),
            _vector(f, "pose.pose.position.", _XYZ, rows),
            _vector(f, "pose.pose.orientation.", "xyzw", rows),
            _vector(f, "twist.twist.linear.", _XYZ, rows),
        )

    return frozenset(wanted), links


def _no_links() -> Transforms:
    empty, text = np.empty(0, np.int64), np.empty(0, dtype=object)
    return Transforms(empty, empty, text, text, np.empty((0, 3)), np.empty((0, 4)))


_DECODERS: dict[str, Callable[..., tuple[frozenset[str], Callable[[dict[str, Level]], Any]]]] = {
    "autoware_perception_msgs/TrackedObjects": lambda: _autoware(True),
    "autoware_auto_perception_msgs/TrackedObjects": lambda: _autoware(True),
    "autoware_perception_msgs/DetectedObjects": lambda: _autoware(False),
    "autoware_auto_perception_msgs/DetectedObjects": lambda: _autoware(False),
    "vision_msgs/Detection3DArray": _vision3d,
    "vision_msgs/Detection2DArray": _vision2d,
    "tf2_msgs/TFMessage": _tf,
    "nav_msgs/Odometry": _odometry,
}

BOX_TYPES = frozenset(name for name in (*_DECODERS, SCENE_UPDATE) if not name.startswith(("tf2_msgs", "nav_msgs")))
"""The message types that give boxes."""

LINK_TYPES = frozenset({"tf2_msgs/TFMessage", "nav_msgs/Odometry"})
"""The message types that give frame links."""

IMAGE_TYPES = frozenset({"vision_msgs/Detection2DArray"})
"""The box types whose boxes are in an image (the others give 3-D boxes)."""


def type_key(schema_name: str) -> str:
    """``pkg/Type`` of a ROS schema name (``pkg/msg/Type`` accepted); a protobuf or JSON schema
    name (``foxglove.SceneUpdate``) as it is."""
    return schema_name if "/" not in schema_name else normalise(schema_name, "")


def supported(schema_name: str, message_encoding: str) -> bool:
    """Whether messages of this schema and encoding are decoded."""
    if schema_name == SCENE_UPDATE:
        return message_encoding in ("json", "protobuf")
    return message_encoding == "cdr" and type_key(schema_name) in _DECODERS


_LAYOUTS: dict[object, Layout] = {}
"""The last layout of each schema and field set decoded (:mod:`.cdr_layout`)."""

_PROGRAMS: dict[object, Program | None] = {}
"""The C walk's program of each schema and field set (:mod:`.cdr_walk`; None: walked in Python)."""


def _walk_program(
    types: dict[str, tuple[Field, ...]], key: str, wanted: frozenset[str], cache_key: object
) -> Program | None:
    if cache_key not in _PROGRAMS:
        try:
            _PROGRAMS[cache_key] = program(types, key, wanted)
        except Unsupported:
            _PROGRAMS[cache_key] = None
    return _PROGRAMS[cache_key]


class TopicBatch:
    """The messages of one topic in a batch (one supported schema and encoding) as they are added,
    each :meth:`add` decoded at once (:mod:`.cdr_batch`: a chunk's messages read while the chunk is
    in memory), into its boxes or links by :meth:`result`. ``capacity``: the messages expected."""

    def __init__(self, first: RawMessage, capacity: int):
        self.error: Exception | None = None
        self.scene: list[RawMessage] | None = [] if first.schema_name == SCENE_UPDATE else None
        self.cdr: CdrBatch | None = None
        if self.scene is not None:
            return
        key = type_key(first.schema_name)
        wanted, self.build = _DECODERS[key](first.topic) if key in IMAGE_TYPES else _DECODERS[key]()
        try:
            types = types_of(first.schema_name, first.schema_data)
            cache_key = (first.schema_name, first.schema_data, wanted)
            plan = _walk_program(types, key, wanted, cache_key)
            self.cdr = CdrBatch(types, key, wanted, cache_key, capacity, _LAYOUTS, plan)
        except (DefinitionError, KeyError) as exc:
            self.error = exc

    def add(self, messages: Sequence[RawMessage]) -> None:
        """Decode the next messages of the topic (a fault is kept for :meth:`result`)."""
        if self.error is not None:
            return
        if self.scene is not None:
            self.scene.extend(messages)
            return
        try:
            self.cdr.add([m.data for m in messages])  # type: ignore[union-attr]
        except (DefinitionError, KeyError) as exc:
            self.error = exc

    def result(self) -> Boxes | ImageBoxes | Transforms:
        """The boxes or links of the messages added: DecodeError names the first bad message (its
        position among them); DefinitionError a schema that cannot be read; KeyError a field the
        decoder needs that the schema lacks."""
        if self.error is not None:
            raise self.error
        if self.scene is not None:
            return decode_scene_updates(self.scene)
        return self.build(self.cdr.levels())  # type: ignore[union-attr]


def decode_batch(messages: Sequence[RawMessage]) -> Boxes | ImageBoxes | Transforms:
    """The boxes or links of a batch of messages of one topic (:class:`TopicBatch`, added at
    once). A batch of one layout is copied by C (:mod:`.cdr_layout`), any other walked in C
    (:mod:`.cdr_walk`), and messages the walk refuses by the generic walk, which names the bad
    message: the same boxes or links each way."""
    batch = TopicBatch(messages[0], len(messages))
    batch.add(messages)
    return batch.result()
