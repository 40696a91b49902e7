"""Label traces written as ``foxglove.SceneUpdate`` messages (JSON or protobuf) in an MCAP file.

One cube entity per object and frame, in the ego's frame ``base_link``, its class in the metadata
key ``class`` and its id the entity's ``id``; the ego's pose in the map frame on ``/tf``
(:mod:`.ros_bag`). The protobuf classes are built from the fields and numbers of
foxglove/schemas' ``.proto`` files (colours, deletions and other primitives left out).
"""

from __future__ import annotations

import json
from pathlib import Path

from ..model import LabelTrace
from .ros_bag import LOG_DELAY_NS, ORIGIN_NS, BagWriter, ego_message, frame_stamps, frames_in_ego_frame
from .ros_messages import Box, pose, stamp


def _foxglove_classes():
    """Protobuf classes of the foxglove schemas written here (fields and numbers of
    foxglove/schemas' .proto files; colours, deletions and other primitives left out)."""
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory, timestamp_pb2

    proto = descriptor_pb2.FileDescriptorProto(
        name="foxglove/SceneUpdate.proto",
        package="foxglove",
        syntax="proto3",
        dependency=["google/protobuf/timestamp.proto"],
    )
    double, string, message = (
        descriptor_pb2.FieldDescriptorProto.TYPE_DOUBLE,
        descriptor_pb2.FieldDescriptorProto.TYPE_STRING,
        descriptor_pb2.FieldDescriptorProto.TYPE_MESSAGE,
    )
    optional, repeated = (
        descriptor_pb2.FieldDescriptorProto.LABEL_OPTIONAL,
        descriptor_pb2.FieldDescriptorProto.LABEL_REPEATED,
    )
    layouts = {
        "Vector3": [
            ("x", 1, double, None, optional),
            ("y", 2, double, None, optional),
            ("z", 3, double, None, optional),
        ],
        "Quaternion": [(a, n, double, None, optional) for n, a in enumerate("xyzw", 1)],
        "Pose": [
            ("position", 1, message, ".foxglove.Vector3", optional),
            ("orientation", 2, message, ".foxglove.Quaternion", optional),
        ],
        "KeyValuePair": [("key", 1, string, None, optional), ("value", 2, string, None, optional)],
        "CubePrimitive": [
            ("pose", 1, message, ".foxglove.Pose", optional),
            ("size", 2, message, ".foxglove.Vector3", optional),
        ],
        "SceneEntity": [
            ("timestamp", 1, message, ".google.protobuf.Timestamp", optional),
            ("frame_id", 2, string, None, optional),
            ("id", 3, string, None, optional),
            ("metadata", 6, message, ".foxglove.KeyValuePair", repeated),
            ("cubes", 8, message, ".foxglove.CubePrimitive", repeated),
        ],
        "SceneUpdate": [("entities", 2, message, ".foxglove.SceneEntity", repeated)],
    }
    for name, fields in layouts.items():
        described = proto.message_type.add(name=name)
        for field_name, number, kind, type_name, label in fields:
            described.field.add(
                name=field_name,
                number=number,
                type=kind,
                label=label,
                **({"type_name": type_name} if type_name else {}),
            )
    pool = descriptor_pool.DescriptorPool()
    pool.AddSerializedFile(timestamp_pb2.DESCRIPTOR.serialized_pb)
    pool.Add(proto)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName("foxglove.SceneUpdate"))


def _cube(update_class, cube: dict):
    """A CubePrimitive of ``update_class``'s file from the dict of a cube."""
    made = update_class.DESCRIPTOR.file.pool.FindMessageTypeByName("foxglove.CubePrimitive")
    from google.protobuf import message_factory

    primitive = message_factory.GetMessageClass(made)()
    for axis in "xyz":
        setattr(primitive.pose.position, axis, cube["pose"]["position"][axis])
        setattr(primitive.size, axis, cube["size"][axis])
    for axis in "xyzw":
        setattr(primitive.pose.orientation, axis, cube["pose"]["orientation"][axis])
    return primitive


def _entities(boxes: list[Box], stamp_ns: int) -> list[dict]:
    return [
        {
            "timestamp": {"sec": stamp_ns // 1_000_000_000, "nsec": stamp_ns % 1_000_000_000},
            "frame_id": "base_link",
            "id": box.id,
            "metadata": [{"key": "class", "value": box.category}],
            "cubes": [{"pose": pose(box), "size": box.size}],
        }
        for box in boxes
    ]


def write_scene_updates(trace: LabelTrace, path: Path, encoding: str, origin_ns: int = ORIGIN_NS) -> None:
    """Write a trace as ``foxglove.SceneUpdate`` messages (one cube entity per object, its class in
    the metadata key ``class``, in ``json`` or ``protobuf``) and the ego's pose on ``/tf``."""
    writer = BagWriter(path)
    mcap = writer.writer._writer
    if encoding == "json":
        schema_id = mcap.register_schema("foxglove.SceneUpdate", "jsonschema", b'{"type": "object"}')
    else:
        from mcap_protobuf.schema import build_file_descriptor_set

        update_class = _foxglove_classes()
        descriptors = build_file_descriptor_set(update_class).SerializeToString()
        schema_id = mcap.register_schema("foxglove.SceneUpdate", "protobuf", descriptors)
    channel = mcap.register_channel("/markers", encoding, schema_id)
    stamps = frame_stamps(trace, origin_ns)
    for f, (ego_pose, boxes) in enumerate(frames_in_ego_frame(trace)):
        log = int(stamps[f]) + LOG_DELAY_NS
        header = {"stamp": stamp(int(stamps[f])), "frame_id": "map"}
        tf = ego_message(ego_pose, (0.0, 0.0), header, "/tf", log)
        writer.write(tf.topic, tf.type_name, tf.message, tf.log_time)
        entities = _entities(boxes, int(stamps[f]))
        if encoding == "json":
            data = json.dumps({"deletions": [], "entities": entities}).encode()
        else:
            update = update_class()
            for entity in entities:
                added = update.entities.add(frame_id=entity["frame_id"], id=entity["id"])
                added.timestamp.seconds, added.timestamp.nanos = entity["timestamp"]["sec"], entity["timestamp"]["nsec"]
                added.metadata.add(**entity["metadata"][0])
                cube = entity["cubes"][0]
                added.cubes.add().CopyFrom(_cube(update_class, cube))
            data = update.SerializeToString()
        mcap.add_message(channel, log, data, log)
    writer.close()
