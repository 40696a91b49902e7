"""A label trace as one Arrow table (the layout of scenegrep's Parquet trace files).

One row per observation, denormalised so that a trace file is directly queryable
with SQL (DuckDB, Polars). Column ``kind`` says what a row is:

- ``state``: an object's kinematic state in a frame (object, class, x..vy, lane, behaviours);
- ``box``: a 2-D detection (sample, channel, image, box_class, score, cx..rotation, oriented; object if tracked);
- ``sample``: a camera sample that has no boxes;
- ``frame``: a frame with neither states nor samples.

Every row carries the frame's ``position`` (0-based order in the trace), ``frame``
(the dataset's frame index) and ``time`` (s). Trace-level fields (name, ego,
objects and their attributes, vocabularies, sources) live in the schema metadata
under the key ``scenegrep`` as JSON.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pyarrow as pa

from .behaviours import BehaviourLabels
from .images import BoxTable, ImageLayer, SampleTable
from .objects import ObjectTable
from .states import FLOAT_COLUMNS, StateTable
from .trace import LabelTrace, MapSource, TraceSource, checked_frame_count
from ..wording import plural

METADATA_KEY = b"scenegrep"
LAYOUT_VERSION = 1
KINDS = ("state", "box", "sample", "frame")

_dict_str = pa.dictionary(pa.int32(), pa.string())
SCHEMA = pa.schema(
    [
        ("kind", _dict_str),
        ("position", pa.int32()),
        ("frame", pa.int64()),
        ("time", pa.float64()),
        ("object", _dict_str),
        ("class", _dict_str),
        *[(name, pa.float64()) for name in FLOAT_COLUMNS],
        ("lane", _dict_str),
        ("behaviours", pa.list_(pa.string())),
        ("behaviour_scores", pa.list_(pa.float32())),
        ("sample", pa.int32()),
        ("channel", _dict_str),
        ("image_path", _dict_str),
        ("image_width", pa.int32()),
        ("image_height", pa.int32()),
        ("box_class", _dict_str),
        ("score", pa.float32()),
        ("cx", pa.float64()),
        ("cy", pa.float64()),
        ("w", pa.float64()),
        ("h", pa.float64()),
        ("rotation", pa.float64()),
        ("oriented", pa.bool_()),
    ]
)


def _dictionary(codes: np.ndarray, vocabulary: Any) -> pa.DictionaryArray:
    """Dictionary array from int codes (-1 = null) into a vocabulary of strings."""
    codes = np.asarray(codes, dtype=np.int32)
    return pa.DictionaryArray.from_arrays(pa.array(codes, mask=codes < 0), pa.array(list(vocabulary), pa.string()))


def _block(n: int, kind: str, position: np.ndarray, trace: LabelTrace, columns: dict[str, Any]) -> pa.Table:
    """A table of n rows of one kind with the given columns; the others are null."""
    arrays = []
    for fld in SCHEMA:
        if fld.name == "kind":
            arrays.append(_dictionary(np.full(n, KINDS.index(kind)), KINDS))
        elif fld.name == "position":
            arrays.append(pa.array(position, pa.int32()))
        elif fld.name == "frame":
            arrays.append(pa.array(trace.frame_index[position], pa.int64()))
        elif fld.name == "time":
            arrays.append(pa.array(trace.frame_time[position], pa.float64()))
        elif fld.name in columns:
            value = columns[fld.name]
            arrays.append(value if isinstance(value, pa.Array) else pa.array(value, fld.type))
        else:
            arrays.append(pa.nulls(n, fld.type))
    return pa.Table.from_arrays(arrays, schema=SCHEMA)


def _label_lists(labels: BehaviourLabels) -> tuple[pa.Array, pa.Array]:
    rows, cols = np.nonzero(labels.member)
    offsets = np.searchsorted(rows, np.arange(len(labels) + 1)).astype(np.int32)
    names = pa.ListArray.from_arrays(
        pa.array(offsets), pa.array(np.array(labels.vocabulary, dtype=object)[cols], pa.string())
    )
    if labels.confidence is None:
        return names, pa.nulls(len(labels), pa.list_(pa.float32()))
    scores = pa.ListArray.from_arrays(
        pa.array(offsets), pa.array(labels.confidence[rows, cols], pa.float32(), from_pandas=True)
    )
    return names, scores


def _state_block(trace: LabelTrace) -> pa.Table:
    s = trace.states
    columns: dict[str, Any] = {name: getattr(s, name) for name in FLOAT_COLUMNS}
    columns["object"] = _dictionary(s.object, trace.objects.id)
    categories, category_code = np.unique(trace.objects.category.astype(str), return_inverse=True)
    columns["class"] = _dictionary(category_code[s.object] if len(s) else np.zeros(0, np.int32), categories)
    columns["lane"] = _dictionary(s.lane, trace.lane_ids)
    if trace.behaviours is not None:
        columns["behaviours"], columns["behaviour_scores"] = _label_lists(trace.behaviours)
    return _block(len(s), "state", s.frame, trace, columns)


def _image_blocks(trace: LabelTrace, images: ImageLayer) -> list[pa.Table]:
    samples, boxes = images.samples, images.boxes

    def sample_columns(rows: np.ndarray) -> dict[str, Any]:
        return {
            "sample": rows,
            "channel": _dictionary(samples.channel[rows], samples.channels),
            "image_path": pa.array(samples.image_path[rows], pa.string()).dictionary_encode(),
            "image_width": samples.image_width[rows],
            "image_height": samples.image_height[rows],
        }

    box_columns = sample_columns(boxes.sample)
    box_columns.update(
        {
            "box_class": _dictionary(boxes.category, boxes.classes),
            "score": boxes.score,
            "cx": boxes.cx,
            "cy": boxes.cy,
            "w": boxes.w,
            "h": boxes.h,
            "rotation": boxes.rotation,
            "oriented": boxes.oriented,
            "object": _dictionary(boxes.object, trace.objects.id),
        }
    )
    empty = np.setdiff1d(np.arange(len(samples)), boxes.sample).astype(np.int32)
    return [
        _block(len(boxes), "box", samples.frame[boxes.sample], trace, box_columns),
        _block(len(empty), "sample", samples.frame[empty], trace, sample_columns(empty)),
    ]


def _metadata(trace: LabelTrace) -> dict[str, Any]:
    images = trace.images
    return {
        "layout": LAYOUT_VERSION,
        "name": trace.name,
        "ego": trace.ego,
        "attributes": dict(trace.attributes),
        "objects": [
            [i, c, a]
            for i, c, a in zip(
                trace.objects.id.tolist(), trace.objects.category.tolist(), trace.objects.attributes.tolist()
            )
        ],
        "lane_ids": list(trace.lane_ids),
        "behaviour_vocabulary": None if trace.behaviours is None else list(trace.behaviours.vocabulary),
        "behaviour_scores": trace.behaviours is not None and trace.behaviours.confidence is not None,
        "channels": None if images is None else list(images.samples.channels),
        "box_classes": None if images is None else list(images.boxes.classes),
        "source": None if trace.source is None else [trace.source.path, trace.source.format],
        "map_source": None
        if trace.map_source is None
        else [trace.map_source.path, trace.map_source.format, trace.map_source.key],
    }


_META_KEYS = (
    "name",
    "ego",
    "attributes",
    "objects",
    "lane_ids",
    "behaviour_vocabulary",
    "behaviour_scores",
    "channels",
    "box_classes",
    "source",
    "map_source",
)
"""The fields of a trace table's metadata besides ``layout`` (see :func:`_metadata`)."""


def trace_to_table(trace: LabelTrace) -> pa.Table:
    """The trace as one Arrow table with the :data:`SCHEMA`, rows ordered by frame position."""
    blocks = [_state_block(trace)]
    covered = np.zeros(trace.n_frames, dtype=bool)
    covered[trace.states.frame] = True
    if trace.images is not None:
        blocks += _image_blocks(trace, trace.images)
        covered[trace.images.samples.frame] = True
    bare = np.flatnonzero(~covered).astype(np.int32)
    blocks.append(_block(len(bare), "frame", bare, trace, {}))
    table = pa.concat_tables(blocks).unify_dictionaries()
    table = table.take(pa.array(np.argsort(table.column("position").to_numpy(), kind="stable")))
    meta = json.dumps(_metadata(trace), separators=(",", ":")).encode()
    return table.replace_schema_metadata({METADATA_KEY: meta})


def is_trace_table(schema: pa.Schema) -> bool:
    """Whether an Arrow schema carries scenegrep trace metadata."""
    return bool(schema.metadata) and METADATA_KEY in schema.metadata


class _Vocabulary(dict):
    """Value -> code; a value the file's vocabulary does not hold is a ValueError naming it."""

    def __missing__(self, value: Any) -> int:
        raise ValueError(f"{value!r} is not in the file's vocabulary")


def _codes(column: pa.ChunkedArray | pa.Array, vocabulary: list[str]) -> np.ndarray:
    """Int codes of a dictionary/string column into ``vocabulary`` (-1 for null)."""
    array = column.combine_chunks() if isinstance(column, pa.ChunkedArray) else column
    position = _Vocabulary({v: k for k, v in enumerate(vocabulary)})
    if isinstance(array.type, pa.DictionaryType):
        lookup = np.array([position[v] for v in array.dictionary.to_pylist()] + [-1], dtype=np.int32)
        idx = array.indices.to_numpy(zero_copy_only=False)
        idx = np.where(array.is_null().to_numpy(zero_copy_only=False), len(lookup) - 1, idx).astype(np.int64)
        return lookup[idx]
    return np.array([-1 if v is None else position[v] for v in array.to_pylist()], dtype=np.int32)


def _numpy(table: pa.Table, name: str, dtype: Any) -> np.ndarray:
    return table.column(name).to_numpy().astype(dtype, copy=False)


def _behaviours(rows: pa.Table, meta: dict[str, Any]) -> BehaviourLabels | None:
    vocabulary = meta["behaviour_vocabulary"]
    if vocabulary is None:
        return None
    names = rows.column("behaviours").combine_chunks()
    offsets = names.offsets.to_numpy()
    flat = _codes(names.flatten(), vocabulary)
    row_of = np.repeat(np.arange(len(rows)), np.diff(offsets))
    member = np.zeros((len(rows), len(vocabulary)), dtype=bool)
    member[row_of, flat] = True
    confidence = None
    if meta["behaviour_scores"]:
        confidence = np.full(member.shape, np.nan, dtype=np.float32)
        scores = rows.column("behaviour_scores").combine_chunks().flatten().to_numpy(zero_copy_only=False)
        confidence[row_of, flat] = scores
    return BehaviourLabels(tuple(vocabulary), member, confidence)


def _images(table: pa.Table, kind: np.ndarray, meta: dict[str, Any], object_ids: list[str]) -> ImageLayer | None:
    if meta["channels"] is None:
        return None
    rows = table.filter(pa.array((kind == 1) | (kind == 2)))
    sample_id = _numpy(rows, "sample", np.int32)
    first = np.unique(sample_id, return_index=True)[1]
    sample_rows = rows.take(pa.array(first))
    samples = SampleTable(
        tuple(meta["channels"]),
        _numpy(sample_rows, "position", np.int32),
        _codes(sample_rows.column("channel"), meta["channels"]),
        np.array(sample_rows.column("image_path").to_pylist(), dtype=object),
        _numpy(sample_rows, "image_width", np.int32),
        _numpy(sample_rows, "image_height", np.int32),
    )
    box_rows = table.filter(pa.array(kind == 1))
    box_rows = box_rows.take(pa.array(np.argsort(_numpy(box_rows, "sample", np.int64), kind="stable")))
    boxes = BoxTable(
        tuple(meta["box_classes"]),
        _numpy(box_rows, "sample", np.int32),
        _codes(box_rows.column("box_class"), meta["box_classes"]),
        _numpy(box_rows, "score", np.float32),
        *[_numpy(box_rows, c, np.float64) for c in ("cx", "cy", "w", "h", "rotation")],
        _numpy(box_rows, "oriented", bool),
        _codes(box_rows.column("object"), object_ids),
    )
    return ImageLayer(samples, boxes)


def trace_from_table(table: pa.Table) -> LabelTrace:
    """Rebuild a trace from a table written by :func:`trace_to_table`; ValueError if it is not one."""
    if not is_trace_table(table.schema):
        raise ValueError("not a scenegrep trace table (no scenegrep metadata)")
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    if meta.get("layout") != LAYOUT_VERSION:
        raise ValueError(f"unsupported trace layout {meta.get('layout')!r} (this scenegrep reads {LAYOUT_VERSION})")
    missing = [name for name in SCHEMA.names if name not in table.column_names]
    if missing:
        raise ValueError(f"missing {plural('column', len(missing))} {', '.join(missing)}")
    absent = [key for key in _META_KEYS if key not in meta]
    if absent:
        raise ValueError(f"missing metadata {plural('field', len(absent))} {', '.join(absent)}")
    kind = _codes(table.column("kind"), list(KINDS))
    position = _numpy(table, "position", np.int64)
    n_frames = checked_frame_count(int(position.max()) + 1 if len(position) else 0)
    frame_index = np.zeros(n_frames, dtype=np.int64)
    frame_time = np.zeros(n_frames)
    frame_index[position] = _numpy(table, "frame", np.int64)
    frame_time[position] = _numpy(table, "time", np.float64)
    ids, categories, attributes = zip(*meta["objects"]) if meta["objects"] else ((), (), ())
    objects = ObjectTable.build(list(ids), list(categories), list(attributes))
    rows = table.filter(pa.array(kind == 0))
    states = StateTable(
        _numpy(rows, "position", np.int32),
        _codes(rows.column("object"), list(ids)),
        *[_numpy(rows, name, np.float64) for name in FLOAT_COLUMNS],
        _codes(rows.column("lane"), meta["lane_ids"]),
    )
    order = np.lexsort((states.object, states.frame))
    rows, states = rows.take(pa.array(order)), states.take(order)
    source, map_source = meta["source"], meta["map_source"]
    return LabelTrace.build(
        meta["name"],
        frame_index,
        frame_time,
        objects,
        states,
        lane_ids=tuple(meta["lane_ids"]),
        behaviours=_behaviours(rows, meta),
        images=_images(table, kind, meta, list(ids)),
        ego=meta["ego"],
        attributes=meta["attributes"],
        source=None if source is None else TraceSource(*source),
        map_source=None if map_source is None else MapSource(*map_source),
    )
