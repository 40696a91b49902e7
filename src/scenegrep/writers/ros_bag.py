"""Label traces written as MCAP files of ROS 2 messages, as an Autoware stack logs them.

:func:`write_tracked` writes a trace's objects as one box message per frame (Autoware
``TrackedObjects`` by default, or ``DetectedObjects`` or ``vision_msgs/Detection3DArray``) in the
ego's frame ``base_link``, and the ego's pose in the map frame ``map`` on ``/tf`` (or as
``nav_msgs/Odometry`` with its twist); :func:`write_detections2d` writes a trace's image boxes as
``vision_msgs/Detection2DArray``. Messages are dicts of :mod:`.ros_messages` encoded to CDR by
mcap-ros2-support's writer (independent of scenegrep's decoder), schemas as rosbag2 writes them.
Frame ``f`` is stamped ``origin_ns`` plus its time, and its messages are logged 20 ms later.
What :mod:`scenegrep.readers.ros` reads back is the trace: objects, kinds, map-frame poses, sizes
and velocities, times; Autoware ids through :func:`.ros_messages.object_uuid`; the ego's size never
(``/tf`` and odometry carry none) and its velocity only from odometry.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from math import cos, sin
from pathlib import Path

import numpy as np
from mcap_ros2.writer import Writer

from ..model import LabelTrace
from ..model.geometry import yaw_from_heading
from .ros_messages import (
    COVARIANCE,
    ZERO,
    Box,
    detected_object,
    detection3d,
    quaternion,
    schema,
    stamp,
    tracked_object,
)

TRACKED_TOPIC = "/perception/object_recognition/tracking/objects"
"""The topic Autoware's tracker publishes ``TrackedObjects`` on."""

ORIGIN_NS = 1_700_000_000_000_000_000
"""The default header stamp of a trace's first frame (2023-11-14 22:13:20 UTC), in nanoseconds."""

LOG_DELAY_NS = 20_000_000
"""How long after its frame's stamp a message is logged."""


@dataclass(frozen=True)
class BagMessage:
    """One message to write: topic, type name (``package/Type``), fields, log time (ns)."""

    topic: str
    type_name: str
    message: dict
    log_time: int


class BagWriter:
    """An MCAP file of ROS 2 messages: each type's schema registered on first use."""

    def __init__(self, path: Path):
        self.writer = Writer(str(path))  # the writer opens the file and closes it on finish
        self.schemas: dict[str, object] = {}

    def write(self, topic: str, type_name: str, message: dict, log_time: int) -> None:
        """Encode and write one message (publish time = log time, nanoseconds)."""
        if type_name not in self.schemas:
            self.schemas[type_name] = self.writer.register_msgdef(type_name.replace("/", "/msg/"), schema(type_name))
        self.writer.write_message(topic, self.schemas[type_name], message, log_time=log_time, publish_time=log_time)

    def close(self) -> None:
        """Write the summary and close the file."""
        self.writer.finish()


def write_messages(path: Path, messages: Iterable[BagMessage]) -> None:
    """Write ``messages`` in the order given as the MCAP file ``path``."""
    writer = BagWriter(path)
    for m in messages:
        writer.write(m.topic, m.type_name, m.message, m.log_time)
    writer.close()


def frame_stamps(trace: LabelTrace, origin_ns: int) -> np.ndarray:
    """The header stamp (ns) of every frame: ``origin_ns`` plus the frame's time."""
    return origin_ns + np.round(trace.frame_time * 1e9).astype(np.int64)


def frames_in_ego_frame(trace: LabelTrace) -> list[tuple[tuple[dict, float], list[Box]]]:
    """Per frame: the ego's pose in the map frame (position dict, yaw) and every other object as a
    :class:`~.ros_messages.Box` in the ego's frame (NaN sizes and velocities kept; an unknown z is 0)."""
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


def ego_message(
    pose: tuple[dict, float], velocity: tuple[float, float], header: dict, topic: str, log_time: int
) -> BagMessage:
    """The ego's pose (map <- base_link) as a ``/tf`` message, or for another ``topic`` as
    ``nav_msgs/Odometry`` with the map-frame ``velocity`` (vx, vy) turned into the ego's frame."""
    position, yaw = pose
    if topic == "/tf":
        link = {"translation": position, "rotation": quaternion(yaw)}
        transforms = [{"header": header, "child_frame_id": "base_link", "transform": link}]
        return BagMessage("/tf", "tf2_msgs/TFMessage", {"transforms": transforms}, log_time)
    with_covariance = {"pose": {"position": position, "orientation": quaternion(yaw)}, "covariance": COVARIANCE}
    vx, vy = velocity  # the twist is in the ego's own frame (base_link)
    linear = {"x": cos(yaw) * vx + sin(yaw) * vy, "y": -sin(yaw) * vx + cos(yaw) * vy, "z": 0.0}
    twist = {"twist": {"linear": linear, "angular": ZERO}, "covariance": COVARIANCE}
    message = {"header": header, "child_frame_id": "base_link", "pose": with_covariance, "twist": twist}
    return BagMessage(topic, "nav_msgs/Odometry", message, log_time)


def tracked_messages(
    trace: LabelTrace,
    origin_ns: int = ORIGIN_NS,
    box_type: str = "autoware_perception_msgs/TrackedObjects",
    ego_topic: str = "/tf",
) -> Iterator[tuple[BagMessage, BagMessage]]:
    """Per frame: the ego's message and the box message of :func:`write_tracked`."""
    stamps = frame_stamps(trace, origin_ns)
    topic, body = BOX_MESSAGES[box_type]
    velocity = np.column_stack([trace.dense(c)[:, trace.object_index(trace.ego)] for c in ("vx", "vy")])
    for f, (pose, boxes) in enumerate(frames_in_ego_frame(trace)):
        log = int(stamps[f]) + LOG_DELAY_NS
        ego = ego_message(
            pose,
            (float(velocity[f, 0]), float(velocity[f, 1])),
            {"stamp": stamp(int(stamps[f])), "frame_id": "map"},
            ego_topic,
            log,
        )
        box_header = {"stamp": stamp(int(stamps[f])), "frame_id": "base_link"}
        yield ego, BagMessage(topic, box_type, {"header": box_header, **body(boxes, box_header)}, log)


def write_tracked(
    trace: LabelTrace,
    path: Path,
    origin_ns: int = ORIGIN_NS,
    box_type: str = "autoware_perception_msgs/TrackedObjects",
    ego_topic: str = "/tf",
) -> None:
    """Write a trace as boxes of ``box_type`` (default TrackedObjects on :data:`TRACKED_TOPIC`),
    in the ``base_link`` frame of the ego, and the ego's pose (map <- base_link) on ``/tf`` or, for
    another ``ego_topic``, as ``nav_msgs/Odometry``; per frame the ego's message, then the boxes."""
    write_messages(path, (m for pair in tracked_messages(trace, origin_ns, box_type, ego_topic) for m in pair))


def camera_topic(channel: str) -> str:
    """The topic a camera channel's detections are written on: ``/CHANNEL/detections``, other
    characters than letters and digits replaced by ``_``."""
    return "/" + "".join(c if c.isalnum() else "_" for c in channel) + "/detections"


def write_detections2d(trace: LabelTrace, path: Path, origin_ns: int = ORIGIN_NS) -> None:
    """Write a trace's image boxes as ``vision_msgs/Detection2DArray``: one message per sample on
    :func:`camera_topic` of its channel, its header frame id the channel, stamped ``origin_ns``
    plus 100 ms per frame position; each box one detection with one hypothesis."""
    writer = BagWriter(path)
    samples, boxes = trace.images.samples, trace.images.boxes
    for k in range(len(samples)):
        at = origin_ns + int(samples.frame[k]) * 100_000_000
        channel = samples.channels[samples.channel[k]]
        header = {"stamp": stamp(at), "frame_id": channel}
        detections = []
        for b in np.flatnonzero(boxes.sample == k):
            hypothesis = {"class_id": boxes.classes[boxes.category[b]], "score": float(boxes.score[b])}
            at_origin = {"pose": {"position": ZERO, "orientation": quaternion(0.0)}, "covariance": COVARIANCE}
            centre = {"position": {"x": float(boxes.cx[b]), "y": float(boxes.cy[b])}, "theta": float(boxes.rotation[b])}
            bbox = {"center": centre, "size_x": float(boxes.w[b]), "size_y": float(boxes.h[b])}
            detections.append(
                {"header": header, "results": [{"hypothesis": hypothesis, "pose": at_origin}], "bbox": bbox, "id": ""}
            )
        writer.write(
            camera_topic(channel), "vision_msgs/Detection2DArray", {"header": header, "detections": detections}, at
        )
    writer.close()
