"""The faults the decoding stage finds before decoding (:mod:`scenegrep.readers.ros.segments`): a
message over the size bound or of another type than its topic's first is the one-line error
naming the first such message's topic and log time; and the C walk's program refuses a type
nested deeper than :data:`~scenegrep.readers.ros.cdr_walk.MAX_DEPTH` (the generic walk then reads
it) rather than recursing without bound."""

from __future__ import annotations

import pytest

from scenegrep.errors import UserError
from scenegrep.readers.ros import segments as segments_module
from scenegrep.readers.ros.cdr_walk import MAX_DEPTH, Unsupported, program
from scenegrep.readers.ros.messages import RawMessage
from scenegrep.readers.ros.msgdef import Field
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.segments import segments
from scenegrep.writers.ros_messages import schema

from .test_ros_cdr import NAME, _message

TF = "tf2_msgs/msg/TFMessage"
ONE = {"xyz": (1.0, 2.0, 3.0), "size": (4.0, 2.0, 1.5), "uuid": b"u" * 16, "classes": [(1, 0.5)], "points": 0}


def _raw(log_time: int, objects: int, name: str = NAME) -> RawMessage:
    data = _message([ONE] * objects, log_time, "map")
    return RawMessage("/objects", name, "ros2msg", schema(name.replace("/msg/", "/")).encode(), "cdr", log_time, data)


@pytest.mark.parametrize(
    ("kinds", "expected"),
    [
        (["ok", "ok", "type", "big"], "message at log time 2 ns: type tf2_msgs/msg/TFMessage on a topic of type"),
        (["ok", "big", "type"], "message at log time 1 ns: a message of {big} bytes (at most {limit})"),
    ],
)
def test_the_first_oversized_or_mistyped_message_is_named(monkeypatch, kinds, expected):
    limit = len(_raw(0, 1).data)
    monkeypatch.setattr(segments_module, "MAX_MESSAGE_BYTES", limit)
    made = {"ok": lambda t: _raw(t, 1), "big": lambda t: _raw(t, 2), "type": lambda t: _raw(t, 1, TF)}
    batch = [made[kind](t) for t, kind in enumerate(kinds)]
    big = len(_raw(0, 2).data)
    assert big > limit
    with pytest.raises(UserError) as caught:
        segments(batch, BagOptions())
    text = str(caught.value)
    assert "\n" not in text and text.startswith("topic /objects, ")
    assert expected.format(big=big, limit=limit) in text


def test_a_message_at_the_size_bound_is_decoded(monkeypatch):
    monkeypatch.setattr(segments_module, "MAX_MESSAGE_BYTES", len(_raw(0, 1).data))
    (found,) = segments([_raw(0, 1), _raw(1, 1)], BagOptions())
    assert found.log_times.tolist() == [0, 1] and len(found.decoded) == 2


def _chain(depth: int) -> dict[str, tuple[Field, ...]]:
    """Types pkg/T0 .. pkg/T<depth>, each but the last holding the next as field ``a``."""
    types = {f"pkg/T{k}": (Field("a", f"pkg/T{k + 1}"),) for k in range(depth)}
    return types | {f"pkg/T{depth}": (Field("x", "float64"),)}


def test_the_walk_program_refuses_nesting_past_its_depth():
    wanted = lambda depth: frozenset({"a." * depth + "x"})  # noqa: E731
    assert len(program(_chain(MAX_DEPTH), "pkg/T0", wanted(MAX_DEPTH)).columns) == 1
    with pytest.raises(Unsupported, match="nested deeper"):
        program(_chain(MAX_DEPTH + 1), "pkg/T0", wanted(MAX_DEPTH + 1))
