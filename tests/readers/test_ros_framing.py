"""Framing (readers/ros/framing.py) on random decoded batches, against a per-row reference: objects
in order of first appearance, the first row of an object in a frame kept, boxes in the ego's frame
moved into the map frame with the ego's pose at their stamp; the string columns as codes
(messages.Coded) or as object arrays give the same trace; the offline run (one trace made at the
end) is the online chunks concatenated."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model import concatenate
from scenegrep.model.geometry import heading_difference
from scenegrep.readers.ros import framing
from scenegrep.readers.ros.framing import FrameBuilder
from scenegrep.readers.ros.messages import Boxes, Coded, RawMessage, Transforms
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.segments import Segment

ORIGIN = 1_700_000_000_000_000_000
STEP = 100_000_000
BOXES, TF = "/objects", "/tf"
SCHEMAS = {BOXES: "autoware_perception_msgs/msg/TrackedObjects", TF: "tf2_msgs/msg/TFMessage"}

coordinate = st.floats(-1e3, 1e3)
angle = st.floats(-math.pi, math.pi)
row = st.tuples(
    st.sampled_from(["a", "b", "c", "d"]),  # object id (repeats within a message too)
    st.sampled_from(["car", "truck"]),
    st.sampled_from(["base_link", "map"]),
    st.tuples(coordinate, coordinate, coordinate),
    angle,
    st.tuples(st.floats(0.5, 5), st.floats(0.5, 5), st.floats(0.5, 5)),
    st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
)
frame = st.tuples(st.lists(row, max_size=5), st.tuples(coordinate, coordinate, coordinate), angle)


def _quat(yaw: float) -> list[float]:
    return [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)]


def _decoded(messages: list[RawMessage], frames: list, coded: bool) -> Boxes | Transforms:
    """What a decoder gives for these messages (each names its frame by its log time)."""
    at = [(m.log_time - ORIGIN) // STEP for m in messages]
    stamps = np.array([ORIGIN + f * STEP for f in at], dtype=np.int64)
    if messages[0].topic == TF:
        xyz = np.array([frames[f][1] for f in at], dtype=float).reshape(-1, 3)
        quat = np.array([_quat(frames[f][2]) for f in at]).reshape(-1, 4)
        names = np.full(len(at), "map", dtype=object), np.full(len(at), "base_link", dtype=object)
        return Transforms(np.arange(len(at)), stamps, *names, xyz, quat)
    rows = [(k, r) for k, f in enumerate(at) for r in frames[f][0]]
    message = np.array([k for k, _ in rows], dtype=np.int64)

    def text(i: int) -> np.ndarray | Coded:
        column = np.empty(len(rows), dtype=object)
        column[:] = [r[i] for _, r in rows]
        return Coded.of(column) if coded else column

    def vectors(values: list, width: int) -> np.ndarray:
        return np.array(values, dtype=float).reshape(len(rows), width)

    return Boxes(
        message,
        stamps[message],
        text(2),
        text(0),
        text(1),
        vectors([r[3] for _, r in rows], 3),
        vectors([_quat(r[4]) for _, r in rows], 4),
        vectors([r[5] for _, r in rows], 3),
        vectors([(*r[6], 0.0) for _, r in rows], 3),
        stamps,
    )


def _batches(n_frames: int, cuts: list[int]) -> list[list[RawMessage]]:
    """Each frame's /tf then its boxes, in batches cut after the given message counts."""
    messages = [
        RawMessage(topic, SCHEMAS[topic], "ros2msg", b"", "cdr", ORIGIN + f * STEP, b"")
        for f in range(n_frames)
        for topic in (TF, BOXES)
    ]
    bounds = sorted({0, len(messages), *(c % len(messages) for c in cuts)})
    return [messages[a:b] for a, b in zip(bounds, bounds[1:])]


def _segments(batch: list[RawMessage], frames: list, coded: bool) -> list[Segment]:
    """A batch's segments as the decoding stage gives them (topics in order of first appearance)."""
    by_topic: dict[str, list[RawMessage]] = {}
    for m in batch:
        by_topic.setdefault(m.topic, []).append(m)
    return [
        Segment(t, SCHEMAS[t], "cdr", np.array([m.log_time for m in ms]), _decoded(ms, frames, coded))
        for t, ms in by_topic.items()
    ]


def _run(frames: list, cuts: list[int], coded: bool, online: bool):
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(framing, "segments", lambda batch, options: _segments(batch, frames, coded))
        builder = FrameBuilder(BagOptions(), "random")
        batches = _batches(len(frames), cuts)
        if not online:
            return builder.run([_segments(b, frames, coded) for b in batches])
        chunks = [c for batch in batches if (c := builder.feed(batch)) is not None]
        last = builder.finish()
        return concatenate(chunks + ([last] if last is not None else []))


def _reference(frames: list) -> tuple[list[str], dict]:
    """Objects in order of first appearance and, per (frame, object), (x, y, z, yaw, l, w, h, vx,
    vy) of its first row, computed row by row in 2-D (the rotations are about +z)."""
    order: dict[str, None] = {}
    states: dict[tuple[int, str], tuple] = {}
    for f, (rows, (ex, ey, ez), ego_yaw) in enumerate(frames):
        for object_id, _, frame_id, (x, y, z), yaw, size, (vx, vy) in rows:
            order.setdefault(object_id)
            if (f, object_id) in states:
                continue
            if frame_id == "base_link":
                c, s = math.cos(ego_yaw), math.sin(ego_yaw)
                x, y, z, yaw = ex + c * x - s * y, ey + s * x + c * y, ez + z, yaw + ego_yaw
            c, s = math.cos(yaw), math.sin(yaw)
            states[f, object_id] = (x, y, z, yaw, *size, c * vx - s * vy, s * vx + c * vy)
        order.setdefault("ego")
        states[f, "ego"] = (ex, ey, ez, ego_yaw, *(math.nan,) * 5)
    return list(order), states


@settings(max_examples=60, deadline=None)
@given(st.lists(frame, min_size=1, max_size=6), st.lists(st.integers(0, 20), max_size=4))
def test_random_batches_frame_as_the_row_by_row_reference_in_every_form(frames, cuts):
    trace = _run(frames, cuts, coded=True, online=False)
    order, states = _reference(frames)
    assert trace.objects.id.tolist() == order
    classes: dict[str, str] = {}  # each object's class where it is first seen
    for rows, _, _ in frames:
        for r in rows:
            classes.setdefault(r[0], r[1])
    assert trace.objects.category.tolist() == [classes.get(i, "ego") for i in order]
    s = trace.states
    assert sorted(zip(s.frame.tolist(), [order[o] for o in s.object])) == sorted(states)
    for k in range(len(s)):
        x, y, z, yaw, length, width, height, vx, vy = states[int(s.frame[k]), order[s.object[k]]]
        expected = [x, y, z, length, width, height, vx, vy]
        found = [s.x[k], s.y[k], s.z[k], s.length[k], s.width[k], s.height[k], s.vx[k], s.vy[k]]
        np.testing.assert_allclose(found, expected, atol=1e-6, equal_nan=True)
        assert abs(heading_difference(s.heading[k], yaw - math.pi / 2)) < 1e-9
    for coded, online in ((False, False), (True, True), (False, True)):
        assert _run(frames, cuts, coded, online).equals(trace)


@given(st.lists(st.sampled_from(["a", "b", "", "ego"]), max_size=12), st.booleans())
def test_a_coded_column_gives_back_its_strings(strings, copies):
    column = np.empty(len(strings), dtype=object)
    column[:] = ["".join(list(s)) for s in strings] if copies else strings  # equal strings as other objects
    coded = Coded.of(column)
    assert coded.strings().tolist() == strings
    assert coded[np.arange(len(strings))[::-1]].strings().tolist() == strings[::-1]


def test_rate_frames_spanning_more_than_a_trace_holds_are_a_user_error():
    """Boxes stamped 1e18 ns apart at --rate 10000 would be 1e13 frames: a one-line error before
    any array is sized by them (was: numpy's MemoryError); the frames complete when the second
    arrives are all but its own."""
    stamps = np.array([ORIGIN, ORIGIN + 10**18], dtype=np.int64)
    text = lambda value: np.array([value, value], dtype=object)  # noqa: E731
    boxes = Boxes(
        np.arange(2), stamps, text("map"), text("a"), text("car"), np.zeros((2, 3)),
        np.tile([0.0, 0.0, 0.0, 1.0], (2, 1)), np.ones((2, 3)), np.zeros((2, 3)), stamps,
    )  # fmt: skip
    segment = Segment(BOXES, SCHEMAS[BOXES], "cdr", stamps, boxes)
    builder = FrameBuilder(BagOptions(rate=10_000.0), "far")
    with pytest.raises(UserError, match=r"^--rate 10000: box stamps from .* make 10000000000000 frames \(a trace"):
        builder.run([[segment]])


def test_an_ego_whose_transforms_arrive_after_the_first_frames_is_the_traces_ego():
    """Frames emitted before the ego's /tf chain is known have no ego row; the ego's rows of the
    later frames still make it the trace's ego, offline and for the online chunks joined (was:
    the first emitted frames' answer, None)."""
    frames = [([("a", "car", "map", (float(f), 0.0, 0.0), 0.0, (4.0, 2.0, 1.5), (1.0, 0.0))], (0.0, 0.0, 0.0), 0.0)
              for f in range(6)]  # fmt: skip
    messages = [RawMessage(BOXES, SCHEMAS[BOXES], "ros2msg", b"", "cdr", ORIGIN + f * STEP, b"") for f in range(3)]
    messages += [
        RawMessage(topic, SCHEMAS[topic], "ros2msg", b"", "cdr", ORIGIN + f * STEP, b"")
        for f in range(3, 6)
        for topic in (TF, BOXES)
    ]
    batches = [messages[:3], messages[3:]]
    trace = FrameBuilder(BagOptions(), "late").run([_segments(b, frames, True) for b in batches])
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(framing, "segments", lambda batch, options: _segments(batch, frames, True))
        builder = FrameBuilder(BagOptions(), "late")
        chunks = [c for batch in batches if (c := builder.feed(batch)) is not None]
        chunks += [last] if (last := builder.finish()) is not None else []
    assert chunks[0].ego is None and concatenate(chunks).equals(trace)
    ego_rows = trace.states.frame[trace.states.object == trace.objects.id.tolist().index("ego")]
    assert trace.n_frames == 6 and 0 < len(ego_rows) < 6
    assert trace.ego == "ego"
