"""ROS 2 messages of a label trace's objects, as dicts for mcap-ros2-support's encoder.

:data:`MSG` holds the message definitions scenegrep writes: the upstream ``.msg`` files' fields
(autoware_msgs 1.12, ros2/common_interfaces, vision_msgs, geometry2's tf2_msgs), comments dropped;
:func:`schema` joins a type's definition with every definition it uses, as rosbag2 writes
``ros2msg`` schemas. The message builders take a :class:`Box` (one object in its message's frame)
and return the message as a dict of fields; mcap-ros2-support encodes it to CDR (an implementation
independent of scenegrep's decoder, :mod:`scenegrep.readers.ros`). Units: metres, radians
(ROS yaw: counter-clockwise from +x), metres per second, nanoseconds.
"""

from __future__ import annotations

import uuid
from dataclasses import dataclass

import math

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
    "vision_msgs/Point2D": "float64 x\nfloat64 y",
    "vision_msgs/Pose2D": "vision_msgs/Point2D position\nfloat64 theta",
    "vision_msgs/BoundingBox2D": "vision_msgs/Pose2D center\nfloat64 size_x\nfloat64 size_y",
    "vision_msgs/Detection2D": (
        "std_msgs/Header header\nObjectHypothesisWithPose[] results\nBoundingBox2D bbox\nstring id"
    ),
    "vision_msgs/Detection2DArray": "std_msgs/Header header\nDetection2D[] detections",
}
"""Message definitions by type name (``package/Type``, the ``msg/`` left out)."""

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
"""The Autoware ``ObjectClassification`` label written for each scenegrep kind."""


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
    """The 16 bytes written for an object id: the UUID itself when the id is one, else its
    UUID version 5 in the URL namespace (so the reader gives back ``str(uuid.UUID(bytes=...))``)."""
    try:
        return uuid.UUID(object_id).bytes
    except ValueError:
        return uuid.uuid5(uuid.NAMESPACE_URL, object_id).bytes


def stamp(ns: int) -> dict:
    """A ``builtin_interfaces/Time`` of ``ns`` nanoseconds."""
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def quaternion(yaw: float) -> dict:
    """The ``geometry_msgs/Quaternion`` of a rotation by ``yaw`` radians about +z."""
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


ZERO = {"x": 0.0, "y": 0.0, "z": 0.0}
COVARIANCE = [0.0] * 36
"""A zero vector and a zero 6 x 6 covariance (row-major), as messages write unknown ones."""


@dataclass(frozen=True)
class Box:
    """One object of a frame as a message carries it: ``position`` (x, y, z dict, metres) and ``yaw``
    (radians) in the message's frame, ``size`` (x length, y width, z height), ``velocity_body``
    (m/s in the object's own frame); ``kind`` is scenegrep's kind, ``category`` the dataset's class."""

    id: str
    kind: str
    category: str
    position: dict
    yaw: float
    size: dict
    velocity_body: dict


def tracked_object(box: Box) -> dict:
    """A TrackedObject message (dict): two classifications, the kind's label (probability 0.75) and
    UNKNOWN (CAR for kind ``other``, 0.25) first, so a reader must take the more probable one; a
    bounding box whose polygon footprint holds ``len(id) % 3`` points (a box ignores its footprint;
    the varied lengths make a frame's objects differ in CDR layout, as polygon shapes do)."""
    return {
        "object_id": {"uuid": list(object_uuid(box.id))},
        "existence_probability": 1.0,
        "classification": [
            {"label": 0 if KIND_LABEL[box.kind] else 1, "probability": 0.25},
            {"label": KIND_LABEL[box.kind], "probability": 0.75},
        ],
        "kinematics": {
            "pose_with_covariance": {"pose": pose(box), "covariance": COVARIANCE},
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
            "pose_with_covariance": {"pose": pose(box), "covariance": COVARIANCE},
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
    with_covariance = {"pose": pose(box), "covariance": COVARIANCE}
    results = [
        {"hypothesis": {"class_id": "unknown", "score": 0.2}, "pose": with_covariance},
        {"hypothesis": {"class_id": box.category, "score": 0.8}, "pose": with_covariance},
    ]
    return {"header": header, "results": results, "bbox": {"center": pose(box), "size": box.size}, "id": box.id}


def pose(box: Box) -> dict:
    """The ``geometry_msgs/Pose`` of a box."""
    return {"position": box.position, "orientation": quaternion(box.yaw)}
