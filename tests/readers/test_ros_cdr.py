"""The vectorised CDR decoder against mcap-ros2-support's encoder: random TrackedObjects (any
number of objects, classifications and footprint points each, so the walk at once and the walk
element by element both run) decode to the values encoded."""

from __future__ import annotations

import uuid

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap_ros2._dynamic import serialize_dynamic

from scenegrep.readers.ros.decoders import AUTOWARE_LABELS, decode_batch
from scenegrep.readers.ros.messages import Coded, RawMessage

from scenegrep.writers.ros_messages import COVARIANCE, ZERO, schema

NAME = "autoware_perception_msgs/TrackedObjects"
ENCODE = serialize_dynamic(NAME.replace("/", "/msg/"), schema(NAME))[NAME.replace("/", "/msg/")]
value = st.floats(-1e6, 1e6)
obj = st.fixed_dictionaries(
    {
        "xyz": st.tuples(value, value, value),
        "size": st.tuples(st.floats(0, 50), st.floats(0, 50), st.floats(0, 50)),
        "classes": st.lists(st.tuples(st.integers(0, 20), st.floats(0, 1, width=32)), max_size=3),
        "points": st.integers(0, 4),
        "uuid": st.binary(min_size=16, max_size=16),
    }
)


def _message(objects: list[dict], sec: int, frame: str) -> bytes:
    def one(o: dict) -> dict:
        pose = {"position": dict(zip("xyz", o["xyz"])), "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}
        return {
            "object_id": {"uuid": list(o["uuid"])},
            "existence_probability": 0.5,
            "classification": [{"label": label, "probability": p} for label, p in o["classes"]],
            "kinematics": {
                "pose_with_covariance": {"pose": pose, "covariance": COVARIANCE},
                "twist_with_covariance": {"twist": {"linear": ZERO, "angular": ZERO}, "covariance": COVARIANCE},
                "acceleration_with_covariance": {"accel": {"linear": ZERO, "angular": ZERO}, "covariance": COVARIANCE},
                "orientation_availability": 1,
                "is_stationary": True,
            },
            "shape": {
                "type": 0,
                "footprint": {"points": [ZERO] * o["points"]},
                "dimensions": dict(zip("xyz", o["size"])),
            },
        }

    header = {"stamp": {"sec": sec, "nanosec": 7}, "frame_id": frame}
    return ENCODE({"header": header, "objects": [one(o) for o in objects]})


@settings(max_examples=100)
@given(
    st.lists(
        st.tuples(st.lists(obj, max_size=5), st.sampled_from(["map", "base_link", "/lidar"])), min_size=1, max_size=4
    )
)
def test_decoded_values_are_the_encoded_ones(messages):
    raw = [
        RawMessage("/o", NAME, "ros2msg", schema(NAME).encode(), "cdr", i, _message(objects, 100 + i, frame))
        for i, (objects, frame) in enumerate(messages)
    ]
    boxes = decode_batch(raw)
    frame_ids, ids, categories = (
        column.strings() if isinstance(column, Coded) else column
        for column in (boxes.frame_id, boxes.id, boxes.category)
    )
    expected = [(i, o, frame) for i, (objects, frame) in enumerate(messages) for o in objects]
    assert len(boxes) == len(expected)
    np.testing.assert_array_equal(boxes.message_stamps, [(100 + i) * 10**9 + 7 for i in range(len(messages))])
    for row, (i, o, frame) in enumerate(expected):
        assert boxes.message[row] == i and frame_ids[row] == frame.lstrip("/")
        np.testing.assert_array_equal(boxes.xyz[row], o["xyz"])
        np.testing.assert_allclose(boxes.size[row], o["size"])
        assert ids[row] == str(uuid.UUID(bytes=o["uuid"]))
        best = max(o["classes"], key=lambda c: c[1], default=(0, 0.0))
        ties = [label for label, p in o["classes"] if p == best[1]]
        label = ties[0] if o["classes"] else 0
        assert categories[row] == (AUTOWARE_LABELS[label] if label < len(AUTOWARE_LABELS) else "UNKNOWN")
