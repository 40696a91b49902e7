"""``foxglove.SceneUpdate`` messages (JSON or protobuf encoded) into :class:`Boxes`.

Every cube primitive of every entity is a box: its pose in the entity's ``frame_id`` at the
entity's ``timestamp``, its ``size`` (x, y, z as length, width, height). The object id is the
entity's ``id`` (``id#k`` for its k-th cube after the first); the class is the value of the
entity's metadata key ``class`` (or ``category``, ``label``), ``unknown`` without one. A message's
stamp is its earliest entity's timestamp (its log time without entities). Deletions and other
primitives are ignored. JSON follows Foxglove's JSON schemas (``timestamp``: ``{"sec", "nsec"}``);
protobuf messages are decoded with the FileDescriptorSet the channel's schema carries.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from .messages import Boxes, DecodeError, RawMessage

SCENE_UPDATE = "foxglove.SceneUpdate"
CLASS_KEYS = ("class", "category", "label")
MAX_ENTITIES = 100_000
"""The most entities a message may hold."""


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{what} is {type(value).__name__}, not a number")
    return float(value)


def _json_entities(data: bytes) -> list[dict]:
    """The entities of a JSON SceneUpdate as plain dicts (ValueError naming what is wrong)."""
    try:
        document = json.loads(bytes(data))
    except (ValueError, RecursionError) as exc:
        raise ValueError(f"not JSON: {str(exc).splitlines()[0] if str(exc) else 'too deeply nested'}") from None
    if not isinstance(document, dict):
        raise ValueError("a SceneUpdate is a JSON object")
    entities = document.get("entities", [])
    if not isinstance(entities, list) or not all(isinstance(e, dict) for e in entities):
        raise ValueError("entities must be a list of objects")
    out = []
    for k, entity in enumerate(entities):
        stamp = entity.get("timestamp") or {}
        cubes = entity.get("cubes") or []
        metadata = entity.get("metadata") or []
        if not isinstance(stamp, dict) or not isinstance(cubes, list) or not isinstance(metadata, list):
            raise ValueError(f"entities[{k}]: timestamp must be an object, cubes and metadata lists")
        sec, nsec = stamp.get("sec", 0), stamp.get("nsec", stamp.get("nanosec", 0))
        out.append(
            {
                "stamp": int(_number(sec, "timestamp.sec")) * 1_000_000_000 + int(_number(nsec, "timestamp.nsec")),
                "frame_id": str(entity.get("frame_id", "")),
                "id": str(entity.get("id", "")),
                "metadata": {str(m.get("key")): str(m.get("value")) for m in metadata if isinstance(m, dict)},
                "cubes": [_json_cube(c, f"entities[{k}].cubes[{j}]") for j, c in enumerate(cubes)],
            }
        )
    return out


def _json_cube(cube: Any, where: str) -> tuple[list[float], list[float], list[float]]:
    if not isinstance(cube, dict):
        raise ValueError(f"{where} is not an object")
    pose = cube.get("pose") or {}
    position, orientation, size = pose.get("position") or {}, pose.get("orientation") or {}, cube.get("size") or {}
    if not all(isinstance(v, dict) for v in (position, orientation, size)):
        raise ValueError(f"{where}: pose.position, pose.orientation and size must be objects")
    return (
        [_number(position.get(a, 0.0), f"{where}.pose.position.{a}") for a in "xyz"],
        [_number(orientation.get(a, 1.0 if a == "w" else 0.0), f"{where}.pose.orientation.{a}") for a in "xyzw"],
        [_number(size.get(a, float("nan")), f"{where}.size.{a}") for a in "xyz"],
    )


@lru_cache(maxsize=16)
def _protobuf_decoder(schema_name: str, schema_encoding: str, schema_data: bytes):
    from mcap.records import Schema
    from mcap_protobuf.decoder import DecoderFactory

    schema = Schema(id=1, name=schema_name, encoding=schema_encoding, data=schema_data)
    decoder = DecoderFactory().decoder_for("protobuf", schema)
    if decoder is None:
        raise ValueError(f"schema {schema_name} ({schema_encoding}) cannot decode protobuf messages")
    return decoder


def _protobuf_entities(message: RawMessage) -> list[dict]:
    update = _protobuf_decoder(message.schema_name, message.schema_encoding, message.schema_data)(bytes(message.data))
    out = []
    for entity in update.entities:
        cubes = [
            (
                [c.pose.position.x, c.pose.position.y, c.pose.position.z],
                [c.pose.orientation.x, c.pose.orientation.y, c.pose.orientation.z, c.pose.orientation.w],
                [c.size.x, c.size.y, c.size.z],
            )
            for c in entity.cubes
        ]
        out.append(
            {
                "stamp": entity.timestamp.seconds * 1_000_000_000 + entity.timestamp.nanos,
                "frame_id": entity.frame_id,
                "id": entity.id,
                "metadata": {m.key: m.value for m in entity.metadata},
                "cubes": cubes,
            }
        )
    return out


def decode_scene_updates(messages: Sequence[RawMessage]) -> Boxes:
    """The cubes of a batch of SceneUpdate messages of one topic (DecodeError names the message)."""
    rows: list[tuple] = []
    stamps = np.zeros(len(messages), dtype=np.int64)
    for i, message in enumerate(messages):
        try:
            if message.message_encoding == "json":
                entities = _json_entities(message.data)
            else:
                entities = _protobuf_entities(message)
        except Exception as exc:  # a library's own error types on a corrupt message
            raise DecodeError(
                i, f"not a valid {SCENE_UPDATE}: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
            ) from None
        if len(entities) > MAX_ENTITIES:
            raise DecodeError(i, f"{len(entities)} entities (at most {MAX_ENTITIES})")
        stamps[i] = min((e["stamp"] for e in entities), default=message.log_time)
        for entity in entities:
            category = next((entity["metadata"][k] for k in CLASS_KEYS if k in entity["metadata"]), "unknown")
            for k, (position, orientation, size) in enumerate(entity["cubes"]):
                object_id = entity["id"] if k == 0 else f"{entity['id']}#{k}"
                rows.append(
                    (
                        i,
                        entity["stamp"],
                        entity["frame_id"].lstrip("/"),
                        object_id,
                        category,
                        position,
                        orientation,
                        size,
                    )
                )
    return _boxes(rows, stamps)


def _boxes(rows: list[tuple], stamps: np.ndarray) -> Boxes:
    def column(k: int, dtype: Any = object) -> np.ndarray:
        out = np.empty(len(rows), dtype=dtype)
        out[:] = [r[k] for r in rows]
        return out

    def matrix(k: int, width: int) -> np.ndarray:
        return np.array([r[k] for r in rows], dtype=np.float64).reshape(len(rows), width)

    return Boxes(
        column(0, np.int64),
        column(1, np.int64),
        column(2),
        column(3),
        column(4),
        matrix(5, 3),
        matrix(6, 4),
        matrix(7, 3),
        np.full((len(rows), 3), np.nan),
        stamps,
    )
