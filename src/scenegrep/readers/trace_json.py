"""scenegrep's own JSON trace format, for hand-written fixtures and small examples.

::

    {"scenegrep": "trace", "version": 1, "name": "lane change", "ego": "car2",
     "frame_interval": 0.1,                      # optional, > 0: time of frame k = k * interval (s)
     "map": {"path": "Town06.xodr", "format": "opendrive"},   # optional; relative to this file;
                                                 # "key" names one map of a file holding several
     "attributes": {"weather": "clear"},         # optional free attributes
     "objects": {"car1": {"class": "Car", "size": [4.5, 2.0, 1.5], "attributes": {"colour": "red"}}},
     "frames": [
       {"index": 0, "time": 0.0,                 # both optional (index defaults to the position)
        "objects": {"car1": {"position": [0, 0], "heading": 0.0, "velocity": [0, 5], "lane": "Lane1",
                             "size": [4.5, 2.0, 1.5], "behaviours": ["FollowLane"]}},
        "samples": [{"channel": "cam::front", "image": "0.png", "image_size": [1920, 1080],
                     "boxes": [{"class": "car", "center": [100, 80], "size": [40, 20], "rotation": 0.0,
                                "score": 0.9, "object": "car1"}]}]}]}

Units: metres, radians (Scenic heading convention), m/s, seconds, pixels for
image boxes. ``position`` is [x, y] or [x, y, z]; ``size`` is [length, width] or
[length, width, height]; a frame's size overrides the object's. ``behaviours`` is
a list of names or an object of name -> confidence (null: no confidence). ``rotation`` marks an
oriented box.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

import msgspec
import numpy as np
from msgspec import Meta, Struct

from ..errors import UserError, at
from ..model import BehaviourLabels, ImageLayer, LabelTrace, MapSource, ObjectTable, StateTable, TraceSource
from ..model.images import ImageLayerBuilder
from .common import display_name, malformed, read_bytes
from .json_locate import msgspec_error

FORMAT = "scenegrep-json"
VERSION = 1

Vector = Annotated[list[float], Meta(min_length=2, max_length=3)]


class _Box(Struct, forbid_unknown_fields=True, rename={"category": "class"}):
    category: str
    center: Annotated[list[float], Meta(min_length=2, max_length=2)]
    size: Annotated[list[float], Meta(min_length=2, max_length=2)]
    rotation: float | None = None
    score: float = 1.0
    object: str | None = None


class _Sample(Struct, forbid_unknown_fields=True):
    channel: str
    image: str = ""
    image_size: Annotated[list[int], Meta(min_length=2, max_length=2)] = msgspec.field(default_factory=lambda: [0, 0])
    boxes: list[_Box] = []


class _State(Struct, forbid_unknown_fields=True):
    position: Vector
    heading: float
    size: Vector | None = None
    velocity: Annotated[list[float], Meta(min_length=2, max_length=2)] | None = None
    lane: str | None = None
    behaviours: list[str] | dict[str, float | None] | None = None


class _Frame(Struct, forbid_unknown_fields=True):
    index: int | None = None
    time: float | None = None
    objects: dict[str, _State] = {}
    samples: list[_Sample] = []


class _Object(Struct, forbid_unknown_fields=True, rename={"category": "class"}):
    category: str
    size: Vector | None = None
    attributes: dict[str, Any] = {}


class _MapRef(Struct, forbid_unknown_fields=True):
    path: str
    format: str
    key: str | None = None


class _Trace(Struct, forbid_unknown_fields=True):
    scenegrep: Literal["trace"]
    version: Literal[1]
    objects: dict[str, _Object]
    frames: list[_Frame]
    name: str | None = None
    ego: str | None = None
    frame_interval: Annotated[float, Meta(gt=0)] | None = None
    map: _MapRef | None = None
    attributes: dict[str, Any] = {}


_DECODER = msgspec.json.Decoder(_Trace)


def sniff(head: bytes) -> bool:
    """Whether the start of a JSON file looks like this format."""
    return b'"scenegrep"' in head and b'"trace"' in head


def _size(state: _State, default: list[float] | None) -> tuple[float, float, float]:
    size = state.size or default or [np.nan, np.nan]
    return (size[0], size[1], size[2] if len(size) > 2 else np.nan)


def _states(doc: _Trace, source: str) -> tuple[StateTable, list, tuple[str, ...]]:
    ids = list(doc.objects)
    row = {oid: i for i, oid in enumerate(ids)}
    cols: dict[str, list] = {
        k: [] for k in ("frame", "object", "x", "y", "z", "heading", "length", "width", "height", "vx", "vy", "lane")
    }
    behaviours: list = []
    lanes: dict[str, int] = {}
    for position, frame in enumerate(doc.frames):
        for oid, state in frame.objects.items():
            if oid not in row:
                raise UserError(
                    f'object {oid!r} is not declared in "objects"', at(source, path=f"frames[{position}].objects")
                )
            length, width, height = _size(state, doc.objects[oid].size)
            vx, vy = state.velocity or (np.nan, np.nan)
            for key, value in (
                ("frame", position),
                ("object", row[oid]),
                ("x", state.position[0]),
                ("y", state.position[1]),
                ("z", state.position[2] if len(state.position) > 2 else np.nan),
                ("heading", state.heading),
                ("length", length),
                ("width", width),
                ("height", height),
                ("vx", vx),
                ("vy", vy),
                ("lane", -1 if state.lane is None else lanes.setdefault(state.lane, len(lanes))),
            ):
                cols[key].append(value)
            behaviours.append(state.behaviours)
    return StateTable.build(**cols), behaviours, tuple(lanes)


def _images(doc: _Trace, object_row: dict[str, int], source: str) -> ImageLayer | None:
    if not any(frame.samples for frame in doc.frames):
        return None
    layer = ImageLayerBuilder()
    for position, frame in enumerate(doc.frames):
        for k, sample in enumerate(frame.samples):
            row = layer.add_sample(position, sample.channel, sample.image, *sample.image_size)
            for box in sample.boxes:
                if box.object is not None and box.object not in object_row:
                    raise UserError(
                        f'box object {box.object!r} is not declared in "objects"',
                        at(source, path=f"frames[{position}].samples[{k}]"),
                    )
                owner = -1 if box.object is None else object_row[box.object]
                layer.add_box(row, box.category, box.score, *box.center, *box.size, box.rotation, owner)
    return layer.build()


def _frame_times(doc: _Trace) -> np.ndarray:
    default = (
        (np.arange(len(doc.frames)) * doc.frame_interval) if doc.frame_interval else np.full(len(doc.frames), np.nan)
    )
    return np.array([default[i] if f.time is None else f.time for i, f in enumerate(doc.frames)], dtype=np.float64)


def decode(data: bytes, source: str, name: str, base_dir: Path | None = None) -> LabelTrace:
    """A trace from the bytes of a scenegrep JSON trace document; UserError naming ``source``
    if it is not one."""
    try:
        doc = _DECODER.decode(data)
    except msgspec.MsgspecError as exc:
        raise msgspec_error(exc, data, 0, source) from None
    with malformed(source, FORMAT):
        return _trace(doc, source, name, base_dir)


def _trace(doc: _Trace, source: str, name: str, base_dir: Path | None) -> LabelTrace:
    objects = ObjectTable.build(
        list(doc.objects), [o.category for o in doc.objects.values()], [o.attributes for o in doc.objects.values()]
    )
    states, labels, lane_ids = _states(doc, source)
    behaviours = None
    if any(label is not None for label in labels):
        behaviours = BehaviourLabels.from_sets(label or () for label in labels)
    if doc.ego is not None and doc.ego not in doc.objects:
        raise UserError(f'ego {doc.ego!r} is not declared in "objects"', at(source, path="ego"))
    map_source = None
    if doc.map is not None:
        map_path = Path(doc.map.path)
        if not map_path.is_absolute() and base_dir is not None:
            map_path = base_dir / map_path
        map_source = MapSource(str(map_path), doc.map.format, doc.map.key)
    index = [position if f.index is None else f.index for position, f in enumerate(doc.frames)]
    return LabelTrace.build(
        doc.name or name,
        index,
        _frame_times(doc),
        objects,
        states,
        lane_ids=lane_ids,
        behaviours=behaviours,
        images=_images(doc, objects.row_of(), source),
        ego=doc.ego,
        attributes=doc.attributes,
        source=TraceSource(source, FORMAT),
        map_source=map_source,
    )


def read_trace(path: str | Path) -> LabelTrace:
    """Read a scenegrep JSON trace file."""
    return decode(read_bytes(path), display_name(path), Path(path).stem, Path(path).parent)
