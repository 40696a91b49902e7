"""The C walk of CDR messages (:mod:`scenegrep.readers.ros.cdr_walk`) against the generic walk
(:mod:`scenegrep.readers.ros.cdr`): random TrackedObjects batches of any layouts (object,
classification and footprint point counts, frame id lengths) read in place from MCAP chunks
give the generic walk's levels (as boxes: every column equal); damaged messages (cut, bytes
changed) are refused by the C walk exactly when the generic walk refuses them; the other
decoders' field sets (/tf, Detection3DArray with strings per item) agree too."""

from __future__ import annotations

import io
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.readers.ros import _cdr_walk
from scenegrep.readers.ros.cdr import CdrError, Payloads, decode
from scenegrep.readers.ros.cdr_walk import decode_walked, program
from scenegrep.readers.ros.chunks import mcap_messages
from scenegrep.readers.ros.decoders import _DECODERS, type_key, types_of

from scenegrep.writers.ros_messages import schema
from .test_ros_cdr import NAME, _message, obj
from .test_ros_cdr_layout import TOPIC, _column, _mcap, _same_boxes

KEY = type_key(NAME)
TYPES = types_of(NAME, schema(NAME).encode())
WANTED, BUILD = _DECODERS[KEY]()
PLAN = program(TYPES, KEY, WANTED)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.lists(obj, max_size=4), st.sampled_from(["map", "base_link", "/lidar", ""])),
        min_size=1,
        max_size=6,
    ),
    st.integers(1, 3000),
)
def test_any_layouts_walk_to_the_generic_levels(messages, chunk_size):
    items = [(TOPIC, i, _message(objects, 100 + i, frame)) for i, (objects, frame) in enumerate(messages)]
    found = [m for m in mcap_messages(io.BytesIO(_mcap(items, chunk_size=chunk_size)), 1 << 24, True)]
    payloads = [m.data for m in found]
    walked = decode_walked(PLAN, payloads)
    assert walked is not None
    _same_boxes(BUILD(walked), BUILD(decode(TYPES, KEY, Payloads.of([bytes(p) for p in payloads]), WANTED)))


def _refused_by_generic(raw: list[bytes]) -> bool:
    try:
        decode(TYPES, KEY, Payloads.of(raw), WANTED)
    except CdrError:
        return True
    return False


@settings(max_examples=120, deadline=None)
@given(
    st.lists(obj, max_size=3),
    st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), max_size=3),
    st.floats(0, 1),
)
def test_damaged_messages_are_refused_exactly_when_the_generic_walk_refuses_them(objects, flips, keep):
    good = _message(objects, 5, "map")
    bad = bytearray(good[: max(4, int(len(good) * keep))])
    for where, value in flips:
        bad[int(len(bad) * where)] = value
    raw = [good, bytes(bad)]
    walked = decode_walked(PLAN, raw)
    assert (walked is None) == _refused_by_generic(raw)
    if walked is not None:
        _same_boxes(BUILD(walked), BUILD(decode(TYPES, KEY, Payloads.of(raw), WANTED)))


def test_a_hostile_count_is_refused():
    raw = bytearray(
        _message([{"xyz": (1, 2, 3), "size": (1, 1, 1), "classes": [], "points": 0, "uuid": b"u" * 16}], 5, "map")
    )
    raw[20:24] = struct.pack("<I", 2**31)  # the object count (after the stamp and frame id "map")
    assert decode_walked(PLAN, [bytes(raw)]) is None and _refused_by_generic([bytes(raw)])


@pytest.mark.parametrize("name", ["tf2_msgs/TFMessage", "vision_msgs/Detection3DArray"])
def test_other_decoders_field_sets_walk_as_the_generic_walk(name):
    from mcap_ros2._dynamic import serialize_dynamic

    full = name.replace("/", "/msg/")
    encode = serialize_dynamic(full, schema(name))[full]
    types = types_of(name, schema(name).encode())
    wanted, build = _DECODERS[type_key(name)]()
    if name.startswith("tf2"):
        link = lambda k: {  # noqa: E731
            "header": {"stamp": {"sec": k, "nanosec": 0}, "frame_id": "map" * k},
            "child_frame_id": f"c{k}",
            "transform": {
                "translation": {"x": k, "y": 0.0, "z": 0.0},
                "rotation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
            },
        }
        raw = [encode({"transforms": [link(k) for k in range(n)]}) for n in (0, 1, 3, 2)]
    else:
        raw = [_detections(encode, n) for n in (0, 2, 1, 3)]
    walked = decode_walked(program(types, type_key(name), wanted), raw)
    assert walked is not None
    fast, slow = build(walked), build(decode(types, type_key(name), Payloads.of(raw), wanted))
    for field in vars(slow):
        np.testing.assert_array_equal(_column(getattr(fast, field)), _column(getattr(slow, field)), err_msg=field)


def _detections(encode, n: int) -> bytes:
    pose = {"position": {"x": 1.0, "y": 2.0, "z": 3.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}
    detection = lambda k: {  # noqa: E731
        "header": {"stamp": {"sec": k, "nanosec": 0}, "frame_id": "cam" if k % 2 else ""},
        "results": [{"hypothesis": {"class_id": f"car{j}", "score": 0.5 + j / 10}} for j in range(k % 3)],
        "bbox": {"center": pose, "size": {"x": 4.0, "y": 2.0, "z": 1.5}},
        "id": f"track-{k}" if k % 2 else "",
    }
    return encode(
        {
            "header": {"stamp": {"sec": n, "nanosec": 1}, "frame_id": "base"},
            "detections": [detection(k) for k in range(n)],
        }
    )


def test_a_bad_program_is_refused_before_it_runs():
    args = ([bytearray()], bytearray(), [bytearray()], [bytearray()], np.zeros(1, np.int64), np.zeros(1, np.int64), 0)
    base, origins, sizes = np.zeros(16, np.uint8), np.array([4], np.int64), np.array([8], np.int64)
    for row in ([1, 3, 1, 0, 0, 0], [1, 8, 1, 5, 0, 0], [5, 3, 0, 1, -1, 0], [5, 0, 9, 1, -1, 0], [9, 0, 0, 0, 0, 0]):
        with pytest.raises(ValueError):
            _cdr_walk.walk(base, origins, sizes, np.array([row], np.int64), *args)
    with pytest.raises(ValueError):  # a message outside its buffer
        _cdr_walk.walk(base, origins, np.array([13], np.int64), np.array([[1, 4, 1, 0, 0, 0]], np.int64), *args)
