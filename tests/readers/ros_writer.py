"""Test writers: label traces written as MCAP bags of ROS 2 messages (CDR through
mcap-ros2-support's own encoder, an implementation independent of the reader's decoder).

Message definitions are the upstream ``.msg`` files' fields (autoware_msgs 1.12,
ros2/common_interfaces, geometry2's tf2_msgs), comments dropped; :func:`schema` joins a type's
definition with every definition it uses, as rosbag2 writes ``ros2msg`` schemas.
"""

from __future__ import annotations

import json
import uuid
from math import cos, sin
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap_ros2.writer import Writer

from scenegrep.model import LabelTrace
from scenegrep.model.geometry import yaw_from_heading

MSG = {
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Point32": "float32 x\nfloat32 y\nfloat32 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/Pose": "Point position\nQuaternion orientation",
    "geometry_msgs/PoseWithCovariance": "Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "Vector3  linear\nVector3  angular",
    "geometry_msgs/TwistWithCovariance": "Twist twist\nfloat64[36] covariance",
    "geometry_msgs/Accel": "Vector3  linear\nVector3  angular",
    "geometry_msgs/AccelWithCovariance": "Accel accel\nfloat64[36] covariance",
    "geometry_msgs/Polygon": "Point32[] points",
    "geometry_msgs/Transform": "Vector3 translation\nQuaternion rotation",
    "geometry_msgs/TransformStamped": "std_msgs/Header header\nstring child_frame_id\nTransform transform",
    "tf2_msgs/TFMessage": "geometry_msgs/TransformStamped[] transforms",
    "nav_msgs/Odometry": (
        "std_msgs/Header header\nstring child_frame_id\n"
        "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist"
    ),
    "unique_identifier_msgs/UUID": "uint8[16] uuid",
    "autoware_perception_msgs/ObjectClassification": (
        "uint8 UNKNOWN = 0\nuint8 CAR = 1\nuint8 TRUCK = 2\nuint8 BUS = 3\nuint8 TRAILER = 4\n"
        "uint8 MOTORCYCLE = 5\nuint8 BICYCLE = 6\nuint8 PEDESTRIAN = 7\nuint8 ANIMAL = 8\nuint8 HAZARD = 9\n"
        "uint8 OVER_DRIVABLE = 10\nuint8 UNDER_DRIVABLE = 11\nuint8 label\nfloat32 probability"
    ),
    "autoware_perception_msgs/Shape": (
        "uint8 BOUNDING_BOX=0\nuint8 CYLINDER=1\nuint8 POLYGON=2\nuint8 type\n"
        "geometry_msgs/Polygon footprint\ngeometry_msgs/Vector3 dimensions"
    ),
    "autoware_perception_msgs/TrackedObjectKinematics": (
        "uint8 UNAVAILABLE=0\nuint8 SIGN_UNKNOWN=1\nuint8 AVAILABLE=2\n"
        "geometry_msgs/PoseWithCovariance pose_with_covariance\n"
        "geometry_msgs/TwistWithCovariance twist_with_covariance\n"
        "geometry_msgs/AccelWithCovariance acceleration_with_covariance\n"
        "uint8 orientation_availability\nbool is_stationary"
    ),
    "autoware_perception_msgs/TrackedObject": (
        "unique_identifier_msgs/UUID object_id\nfloat32 existence_probability\n"
        "ObjectClassification[] classification\nTrackedObjectKinematics kinematics\nShape shape"
    ),
    "autoware_perception_msgs/TrackedObjects": "std_msgs/Header header\nTrackedObject[] objects",
    "autoware_perception_msgs/DetectedObjectKinematics": (
        "uint8 UNAVAILABLE=0\nuint8 SIGN_UNKNOWN=1\nuint8 AVAILABLE=2\n"
        "geometry_msgs/PoseWithCovariance pose_with_covariance\nbool has_position_covariance\n"
        "uint8 orientation_availability\ngeometry_msgs/TwistWithCovariance twist_with_covariance\n"
        "bool has_twist\nbool has_twist_covariance"
    ),
    "autoware_perception_msgs/DetectedObject": (
        "float32 existence_probability\nObjectClassification[] classification\n"
        "DetectedObjectKinematics kinematics\nShape shape"
    ),
    "autoware_perception_msgs/DetectedObjects": "std_msgs/Header header\nDetectedObject[] objects",
    "vision_msgs/ObjectHypothesis": "string class_id\nfloat64 score",
    "vision_msgs/ObjectHypothesisWithPose": "ObjectHypothesis hypothesis\ngeometry_msgs/PoseWithCovariance pose",
    "vision_msgs/BoundingBox3D": "geometry_msgs/Pose center\ngeometry_msgs/Vector3 size",
    "vision_msgs/Detection3D": (
        "std_msgs/Header header\nObjectHypothesisWithPose[] results\nBoundingBox3D bbox\nstring id"
    ),
    "vision_msgs/Detection3DArray": "std_msgs/Header header\nDetection3D[] detections",
}

KIND_LABEL = {
    "car": 1,
    "truck": 2,
    "bus": 3,
    "trailer": 4,
    "motorcycle": 5,
    "bicycle": 6,
    "pedestrian": 7,
    "animal": 8,
    "static": 9,
    "other": 0,
}
"""The Autoware label a test writes for each scenegrep kind."""

TRACKED_TOPIC = "/perception/object_recognition/tracking/objects"

ORIGIN_NS = 1_700_000_000_000_000_000
"""The header stamp a test writes for a trace's first frame (2023-11-14)."""


def _uses(name: str) -> list[str]:
    package = name.split("/")[0]
    found = []
    for line in MSG[name].splitlines():
        words = line.split()
        if len(words) < 2 or "=" in words[1] or (len(words) > 2 and words[2].startswith("=")):
            continue
        base = words[0].split("[")[0]
        if base[0].isupper() or "/" in base:
            found.append(base if "/" in base else f"{package}/{base}")
    return found


def schema(name: str) -> str:
    """The ``ros2msg`` schema text of a type: its definition, then every type it uses."""
    order: list[str] = []
    todo = _uses(name)
    while todo:
        used = todo.pop(0)
        if used not in order:
            order.append(used)
            todo.extend(_uses(used))
    parts = [MSG[name]] + [f"{'=' * 80}\nMSG: {u.replace('/', '/msg/')}\n{MSG[u]}" for u in order]
    return "\n".join(parts)


def object_uuid(object_id: str) -> bytes:
    """The 16 bytes a test writes for an object id: the UUID itself when the id is one."""
    try:
        return uuid.UUID(object_id).bytes
    except ValueError:
        return uuid.uuid5(uuid.NAMESPACE_URL, object_id).bytes


def read_back_id(object_id: str) -> str:
    """The id the reader gives back for an object written with :func:`object_uuid`."""
    return str(uuid.UUID(bytes=object_uuid(object_id)))


def _stamp(ns: int) -> dict:
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def _quat(yaw: float) -> dict:
    return {"x": 0.0, "y": 0.0, "z": float(np.sin(yaw / 2)), "w": float(np.cos(yaw / 2))}


def frame_stamps(trace: LabelTrace, origin_ns: int) -> np.ndarray:
    """The header stamp (ns) a test writes for every frame."""
    return origin_ns + np.round(trace.frame_time * 1e9).astype(np.int64)


class BagWriter:
    """An MCAP file of ROS 2 messages: register types once, write dict messages."""

    def __init__(self, path: Path):
        self.writer = Writer(str(path))  # the writer opens the file and closes it on finish
        self.schemas: dict[str, object] = {}

    def write(self, topic: str, type_name: str, message: dict, log_time: int) -> None:
        if type_name not in self.schemas:
            self.schemas[type_name] = self.writer.register_msgdef(type_name.replace("/", "/msg/"), schema(type_name))
        self.writer.write_message(topic, self.schemas[type_name], message, log_time=log_time, publish_time=log_time)

    def close(self) -> None:
        self.writer.finish()


ZERO = {"x": 0.0, "y": 0.0, "z": 0.0}
COVARIANCE = [0.0] * 36


@dataclass(frozen=True)
class Box:
    """One object of a frame as a message carries it: pose in the ego frame (``base_link``)."""

    id: str
    kind: str
    category: str
    position: dict
    yaw: float
    size: dict
    velocity_body: dict


def tracked_object(box: Box) -> dict:
    """A TrackedObject message (dict): two classifications, the kind's label the more probable."""
    return {
        "object_id": {"uuid": list(object_uuid(box.id))},
        "existence_probability": 1.0,
        "classification": [
            {"label": 0 if KIND_LABEL[box.kind] else 1, "probability": 0.25},
            {"label": KIND_LABEL[box.kind], "probability": 0.75},
        ],
        "kinematics": {
            "pose_with_covariance": {"pose": _pose(box), "covariance": COVARIANCE},
            "twist_with_covariance": {
                "twist": {"linear": box.velocity_body, "angular": ZERO},
                "covariance": COVARIANCE,
            },
            "acceleration_with_covariance": {"accel": {"linear": ZERO, "angular": ZERO}, "covariance": COVARIANCE},
            "orientation_availability": 2,
            "is_stationary": False,
        },
        "shape": {
            "type": 0,
            "footprint": {"points": [{"x": 1.0, "y": 2.0, "z": 0.0}] * (len(box.id) % 3)},
            "dimensions": box.size,
        },
    }


def detected_object(box: Box) -> dict:
    """A DetectedObject message (dict): no id; the twist given (``has_twist``)."""
    return {
        "existence_probability": 1.0,
        "classification": [{"label": KIND_LABEL[box.kind], "probability": 0.9}],
        "kinematics": {
            "pose_with_covariance": {"pose": _pose(box), "covariance": COVARIANCE},
            "has_position_covariance": False,
            "orientation_availability": 2,
            "twist_with_covariance": {
                "twist": {"linear": box.velocity_body, "angular": ZERO},
                "covariance": COVARIANCE,
            },
            "has_twist": True,
            "has_twist_covariance": False,
        },
        "shape": {"type": 0, "footprint": {"points": []}, "dimensions": box.size},
    }


def detection3d(box: Box, header: dict) -> dict:
    """A vision_msgs Detection3D (dict): two hypotheses, the object's class the more probable; its
    tracking id; its own header (the array's)."""
    pose = {"pose": _pose(box), "covariance": COVARIANCE}
    results = [
        {"hypothesis": {"class_id": "unknown", "score": 0.2}, "pose": pose},
        {"hypothesis": {"class_id": box.category, "score": 0.8}, "pose": pose},
    ]
    return {"header": header, "results": results, "bbox": {"center": _pose(box), "size": box.size}, "id": box.id}


def _pose(box: Box) -> dict:
    return {"position": box.position, "orientation": _quat(box.yaw)}


def frames_in_ego_frame(trace: LabelTrace) -> list[tuple[dict, list[Box]]]:
    """Per frame: the ego's pose in the map frame (position dict, yaw) and every other object as a
    :class:`Box` in the ego's frame (NaN sizes and velocities kept; an unknown z is 0)."""
    ego = trace.object_index(trace.ego)
    ex, ey, ez, eh = (trace.dense(c)[:, ego] for c in ("x", "y", "z", "heading"))
    ez = np.nan_to_num(ez)
    kinds = trace.objects.kinds()
    offsets = trace.states.frame_offsets(trace.n_frames)
    s = trace.states
    out = []
    for f in range(trace.n_frames):
        ego_yaw = float(yaw_from_heading(eh[f]))
        c, si = np.cos(ego_yaw), np.sin(ego_yaw)
        boxes = []
        for r in range(offsets[f], offsets[f + 1]):
            o = int(s.object[r])
            if o == ego:
                continue
            dx, dy, dz = s.x[r] - ex[f], s.y[r] - ey[f], np.nan_to_num(s.z[r]) - ez[f]
            yaw = float(yaw_from_heading(s.heading[r]))
            cb, sb = np.cos(yaw), np.sin(yaw)
            vx, vy = float(s.vx[r]), float(s.vy[r])
            boxes.append(
                Box(
                    str(trace.objects.id[o]),
                    str(kinds[o]),
                    str(trace.objects.category[o]),
                    {"x": c * dx + si * dy, "y": -si * dx + c * dy, "z": float(dz)},
                    yaw - ego_yaw,
                    {"x": float(s.length[r]), "y": float(s.width[r]), "z": float(s.height[r])},
                    {"x": cb * vx + sb * vy, "y": -sb * vx + cb * vy, "z": 0.0},
                )
            )
        ego_pose = {"x": float(ex[f]), "y": float(ey[f]), "z": float(ez[f])}
        out.append(((ego_pose, ego_yaw), boxes))
    return out


BOX_MESSAGES = {
    "autoware_perception_msgs/TrackedObjects": (
        TRACKED_TOPIC,
        lambda boxes, header: {"objects": [tracked_object(b) for b in boxes]},
    ),
    "autoware_perception_msgs/DetectedObjects": (
        "/perception/object_recognition/detection/objects",
        lambda boxes, header: {"objects": [detected_object(b) for b in boxes]},
    ),
    "vision_msgs/Detection3DArray": (
        "/detections_3d",
        lambda boxes, header: {"detections": [detection3d(b, header) for b in boxes]},
    ),
}
"""Per box message type: its topic and the message body of a frame's boxes."""


def write_tracked(
    trace: LabelTrace,
    path: Path,
    origin_ns: int = ORIGIN_NS,
    drop: frozenset[int] = frozenset(),
    late_tf: bool = False,
    box_type: str = "autoware_perception_msgs/TrackedObjects",
    ego_topic: str = "/tf",
) -> None:
    """Write a trace as boxes of ``box_type`` (default TrackedObjects on :data:`TRACKED_TOPIC`),
    in the ``base_link`` frame of the ego, and the ego's pose (map <- base_link) on ``/tf`` or, for
    another ``ego_topic``, as ``nav_msgs/Odometry``; one of each per frame, logged 20 ms after the
    frame's stamp. ``drop``: frame positions whose box message is not written; ``late_tf``: each
    frame's /tf message is written after the next frame's boxes (out of order)."""
    writer = BagWriter(path)
    stamps = frame_stamps(trace, origin_ns)
    topic, body = BOX_MESSAGES[box_type]
    ego_velocity = np.column_stack([trace.dense(c)[:, trace.object_index(trace.ego)] for c in ("vx", "vy")])
    pending_tf = None
    for f, ((ego_pose, ego_yaw), boxes) in enumerate(frames_in_ego_frame(trace)):
        header = {"stamp": _stamp(int(stamps[f])), "frame_id": "map"}
        if ego_topic == "/tf":
            link = {"translation": ego_pose, "rotation": _quat(ego_yaw)}
            ego = (
                "/tf",
                "tf2_msgs/TFMessage",
                {"transforms": [{"header": header, "child_frame_id": "base_link", "transform": link}]},
            )
        else:
            pose = {"pose": {"position": ego_pose, "orientation": _quat(ego_yaw)}, "covariance": COVARIANCE}
            vx, vy = ego_velocity[f]  # the twist is in the ego's own frame (base_link)
            linear = {"x": cos(ego_yaw) * vx + sin(ego_yaw) * vy, "y": -sin(ego_yaw) * vx + cos(ego_yaw) * vy, "z": 0.0}
            twist = {"twist": {"linear": linear, "angular": ZERO}, "covariance": COVARIANCE}
            message = {"header": header, "child_frame_id": "base_link", "pose": pose, "twist": twist}
            ego = (ego_topic, "nav_msgs/Odometry", message)
        log = int(stamps[f]) + 20_000_000
        if not late_tf:
            writer.write(*ego, log)
        if f not in drop:
            box_header = {"stamp": _stamp(int(stamps[f])), "frame_id": "base_link"}
            message = {"header": box_header, **body(boxes, box_header)}
            writer.write(topic, box_type, message, log)
        if late_tf:
            if pending_tf is not None:
                writer.write(*pending_tf)
            pending_tf = (*ego, log)
    if pending_tf is not None:
        writer.write(*pending_tf)
    writer.close()


def _foxglove_classes():
    """Protobuf classes of the foxglove schemas the tests write (fields and numbers of
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
            "cubes": [{"pose": _pose(box), "size": box.size}],
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
    for f, ((ego_pose, ego_yaw), boxes) in enumerate(frames_in_ego_frame(trace)):
        log = int(stamps[f]) + 20_000_000
        header = {"stamp": _stamp(int(stamps[f])), "frame_id": "map"}
        link = {"translation": ego_pose, "rotation": _quat(ego_yaw)}
        writer.write(
            "/tf",
            "tf2_msgs/TFMessage",
            {"transforms": [{"header": header, "child_frame_id": "base_link", "transform": link}]},
            log,
        )
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


def _add_vision2d() -> None:
    MSG.update(
        {
            "vision_msgs/Point2D": "float64 x\nfloat64 y",
            "vision_msgs/Pose2D": "vision_msgs/Point2D position\nfloat64 theta",
            "vision_msgs/BoundingBox2D": "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y",
            "vision_msgs/Detection2D": (
                "std_msgs/Header header\nObjectHypothesisWithPose[] results\nBoundingBox2D bbox\nstring id"
            ),
            "vision_msgs/Detection2DArray": "std_msgs/Header header\nDetection2D[] detections",
        }
    )


_add_vision2d()


def camera_topic(channel: str) -> str:
    """The topic a test writes a camera channel's detections on."""
    return "/" + "".join(c if c.isalnum() else "_" for c in channel) + "/detections"


def write_detections2d(trace: LabelTrace, path: Path, origin_ns: int = ORIGIN_NS) -> None:
    """Write a trace's image boxes as ``vision_msgs/Detection2DArray``: one message per sample on
    :func:`camera_topic` of its channel, its header frame id the channel, stamped ``origin_ns``
    plus 100 ms per frame position; each box one detection with one hypothesis."""
    writer = BagWriter(path)
    samples, boxes = trace.images.samples, trace.images.boxes
    for k in range(len(samples)):
        stamp = origin_ns + int(samples.frame[k]) * 100_000_000
        channel = samples.channels[samples.channel[k]]
        header = {"stamp": _stamp(stamp), "frame_id": channel}
        detections = []
        for b in np.flatnonzero(boxes.sample == k):
            hypothesis = {"class_id": boxes.classes[boxes.category[b]], "score": float(boxes.score[b])}
            pose = {"pose": {"position": ZERO, "orientation": _quat(0.0)}, "covariance": COVARIANCE}
            centre = {"position": {"x": float(boxes.cx[b]), "y": float(boxes.cy[b])}, "theta": float(boxes.rotation[b])}
            bbox = {"center": centre, "size_x": float(boxes.w[b]), "size_y": float(boxes.h[b])}
            detections.append(
                {"header": header, "results": [{"hypothesis": hypothesis, "pose": pose}], "bbox": bbox, "id": ""}
            )
        writer.write(
            camera_topic(channel), "vision_msgs/Detection2DArray", {"header": header, "detections": detections}, stamp
        )
    writer.close()
