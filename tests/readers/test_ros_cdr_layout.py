"""The one-layout CDR decoder (:mod:`scenegrep.readers.ros.cdr_layout`) against the generic walk,
through real MCAP files: random TrackedObjects drawn from one or two layouts (so batches of one
layout and mixed batches both occur, also inside one chunk), other messages of random sizes
between them (so a chunk's messages are evenly spaced or not), small chunks, every
compression; read in place from the chunks. A batch is decoded on the fast path exactly when
every message has one layout, and then to the boxes the generic walk gives; a bad message in
a batch of one layout is still the generic walk's one-line error naming topic and log time."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.writer import CompressionType, Writer

from scenegrep import readers
from scenegrep.errors import UserError
from scenegrep.readers.ros.cdr import Payloads, decode
from scenegrep.readers.ros import _cdr_copy
from scenegrep.readers.ros.cdr_batch import CdrBatch
from scenegrep.readers.ros.cdr_layout import Unsupported, layout
from scenegrep.readers.ros.chunks import mcap_messages
from scenegrep.readers.ros.decoders import _DECODERS, decode_batch, type_key, types_of
from scenegrep.readers.ros.messages import Coded

from scenegrep.writers.ros_messages import schema
from .test_ros_cdr import NAME, _message, obj

KEY = type_key(NAME)
TYPES = types_of(NAME, schema(NAME).encode())
WANTED, BUILD = _DECODERS[KEY]()
FIELDS = ("message", "stamp", "frame_id", "id", "category", "xyz", "quat", "size", "velocity", "message_stamps")
TOPIC = "/objects"


def _shape(objects: list[dict]) -> tuple:
    return tuple((len(o["classes"]), o["points"]) for o in objects)


def _mcap(items: list[tuple[str, int, bytes]], compression=CompressionType.ZSTD, chunk_size: int = 1 << 20) -> bytes:
    """An MCAP file of (topic, log time, data): TOPIC as TrackedObjects, others as raw bytes."""
    out = io.BytesIO()
    writer = Writer(out, chunk_size=chunk_size, compression=compression)
    writer.start("ros2", "test")
    channels: dict[str, int] = {}
    for topic, log_time, data in items:
        if topic not in channels:
            name, text = (NAME.replace("/", "/msg/"), schema(NAME)) if topic == TOPIC else ("pkg/msg/Other", "int8 x")
            registered = writer.register_schema(name, "ros2msg", text.encode())
            channels[topic] = writer.register_channel(topic, "cdr", registered)
        writer.add_message(channels[topic], log_time=log_time, data=data, publish_time=log_time)
    writer.finish()
    return out.getvalue()


def _column(column):
    """A column as an array (a coded string column as its strings)."""
    return column.strings() if isinstance(column, Coded) else column


def _same_boxes(fast, slow) -> None:
    for name in FIELDS:
        np.testing.assert_array_equal(_column(getattr(fast, name)), _column(getattr(slow, name)), err_msg=name)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.lists(obj, max_size=3), min_size=1, max_size=2),
    st.lists(st.tuples(st.integers(0, 1), st.integers(0, 10**6), st.integers(-1, 40)), min_size=1, max_size=8),
    st.sampled_from(["map", "base_link"]),
    st.sampled_from([CompressionType.NONE, CompressionType.LZ4, CompressionType.ZSTD]),
    st.integers(1, 3000),
    st.booleans(),
)
def test_batches_read_in_place_decode_as_the_generic_walk(pool, picks, frame, compression, chunk_size, stale):
    chosen = [pool[k % len(pool)] for k, _, _ in picks]
    items = []
    for i, (objects, (_, sec, other)) in enumerate(zip(chosen, picks)):
        items.append((TOPIC, i, _message(objects, sec, frame)))
        if other >= 0:  # another topic's message between them: their spacing in a chunk changes
            items.append(("/other", i, bytes(other)))
    found = [m for m in mcap_messages(io.BytesIO(_mcap(items, compression, chunk_size)), 1 << 24, True)]
    payloads = [m.data for m in found if m.topic == TOPIC]
    assert all(isinstance(p, memoryview) for p in payloads)
    # a cache holding the other layout of the pool first, or nothing
    cache = {}
    if stale and len(pool) > 1:
        cache["k"] = layout(TYPES, KEY, WANTED, _message(pool[1], 0, frame)[4:])
    levels = _one_layout(payloads, cache)
    slow = BUILD(decode(TYPES, KEY, Payloads.of([bytes(p) for p in payloads]), WANTED))
    assert (levels is not None) == all(_shape(o) == _shape(chosen[0]) for o in chosen)
    if levels is not None:
        _same_boxes(BUILD(levels), slow)
    _same_boxes(decode_batch([m for m in found if m.topic == TOPIC]), slow)


def _one_layout(payloads: list, cache: dict):
    """The levels of a batch decoded as one layout (a :class:`CdrBatch` without the C walk, its
    layout ``cache["k"]``'s when the first message is of it, else the first message's), or None
    when not every message was copied on that layout."""
    batch = CdrBatch(TYPES, KEY, WANTED, "k", len(payloads), cache, None)
    batch.add(payloads)
    return batch.levels() if batch.mode == "layout" else None


def _equal_sizes() -> tuple[list[dict], list[dict]]:
    """Two one-object messages of equal size and different layouts (classes and points)."""
    one = {"xyz": (1.0, 2.0, 3.0), "size": (4.0, 2.0, 1.5), "uuid": b"u" * 16}
    sizes: dict[int, list[dict]] = {}
    for classes in range(4):
        for points in range(5):
            o = one | {"classes": [(1, 0.5)] * classes, "points": points}
            size = len(_message([o], 0, "map"))
            if size in sizes:
                return sizes[size], [o]
            sizes[size] = [o]
    raise AssertionError("no two layouts of one size")


def test_equal_sizes_with_other_counts_are_not_one_layout():
    a, b = _equal_sizes()
    raw = [_message(a, 1, "map"), _message(b, 2, "map")]
    assert len(raw[0]) == len(raw[1])
    assert _one_layout([memoryview(r) for r in raw], {}) is None
    slow = BUILD(decode(TYPES, KEY, Payloads.of(raw), WANTED))
    _same_boxes(decode_batch([_raw(r, i) for i, r in enumerate(raw)]), slow)


def _raw(data: bytes, log_time: int):
    from scenegrep.readers.ros.messages import RawMessage

    return RawMessage(TOPIC, NAME, "ros2msg", schema(NAME).encode(), "cdr", log_time, memoryview(data))


def test_a_truncated_message_has_no_layout():
    raw = _message(
        [{"xyz": (1, 2, 3), "size": (1, 1, 1), "classes": [(1, 0.5)], "points": 2, "uuid": b"u" * 16}], 5, "map"
    )
    for cut in (3, 40, len(raw) - 5):
        with pytest.raises(Unsupported, match="truncated"):
            layout(TYPES, KEY, WANTED, raw[4:cut])
    hostile = bytearray(raw)
    hostile[20:24] = struct.pack("<I", 2**31)  # the object count (frame id "map": after 16 bytes of CDR)
    with pytest.raises(Unsupported, match="count too large"):
        layout(TYPES, KEY, WANTED, bytes(hostile[4:]))


OBJECTS = [{"xyz": (k, 2.0, 0.0), "size": (4.0, 2.0, 1.5), "classes": [(1, 0.9)], "points": 0} for k in range(3)]
UNIFORM = [_message([o | {"uuid": bytes([k]) * 16} for k, o in enumerate(OBJECTS)], 100 + i, "map") for i in range(30)]


@pytest.mark.parametrize(
    "damage",
    [
        lambda data: data[:-9],  # truncated: its size differs from the others'
        lambda data: data[:20] + struct.pack("<I", 2**30) + data[24:],  # same size, hostile object count
        lambda data: b"\0\0" + data[2:],  # big-endian header
    ],
    ids=["truncated", "count too large", "header"],
)
def test_a_bad_message_in_a_uniform_chunk_is_the_generic_error(tmp_path: Path, damage):
    path = tmp_path / "bad.mcap"
    bad = [(TOPIC, 1_000 + i, damage(data) if i == 17 else data) for i, data in enumerate(UNIFORM)]
    path.write_bytes(_mcap(bad))
    with pytest.raises(UserError) as error:
        readers.read_trace(path, "ros-bag")
    line = error.value.one_line()
    assert "\n" not in line and f"topic {TOPIC}, message at log time {1_017} ns:" in line


def test_a_message_of_the_same_size_and_another_count_is_read_as_the_generic_walk_reads_it(tmp_path: Path):
    path = tmp_path / "fewer.mcap"
    messages = list(UNIFORM)
    messages[17] = messages[17][:20] + struct.pack("<I", 2) + messages[17][24:]  # one object fewer, same bytes
    path.write_bytes(_mcap([(TOPIC, 1_000 + i, data) for i, data in enumerate(messages)]))
    trace = readers.read_trace(path, "ros-bag")
    per_frame = np.bincount(trace.states.frame, minlength=trace.n_frames)
    assert per_frame.tolist() == [3] * 17 + [2] + [3] * 12


def _run(origins, size, copies, row_bytes=16, out_len=64, count_at=(), base_len=64):
    out = np.zeros(out_len, np.uint8)
    return _cdr_copy.run(
        np.zeros(base_len, np.uint8),
        np.array(origins, np.int64),
        size,
        np.array(count_at, np.int64),
        np.zeros(len(count_at), np.uint32),
        np.array(copies, np.int64).reshape(-1, 4),
        (out,),
        np.array([row_bytes], np.int64),
        0,
    )


@pytest.mark.parametrize(
    ("origins", "size", "copies", "count_at"),
    [
        ([60], 8, [(0, 0, 0, 4)], ()),  # the message runs past its buffer
        ([2], 8, [(0, 0, 0, 4)], ()),  # no room for its header
        ([4], 8, [(6, 0, 0, 4)], ()),  # a copy past the message
        ([4], 8, [(0, 0, 14, 4)], ()),  # a copy past its output row
        ([4], 8, [(0, 1, 0, 4)], ()),  # an output that is not there
        ([4] * 5, 8, [(0, 0, 0, 4)], ()),  # more rows than the output holds
        ([4], 8, [(0, 0, 0, -1)], ()),  # a negative length
        ([4], 8, [], (6,)),  # a count past the message
    ],
)
def test_the_copy_plan_is_bounds_checked_before_it_runs(origins, size, copies, count_at):
    with pytest.raises(ValueError):
        _run(origins, size, copies, count_at=count_at)


def test_the_copy_plan_stops_at_the_first_message_of_another_layout():
    base = np.zeros(64, np.uint8)
    base[[1, 17, 33]] = 1  # encapsulation headers 00 01 at 0, 16, 32 (origins 4, 20, 36)
    base[20:24] = [7, 0, 0, 0]  # message 1's count
    out = np.zeros(48, np.uint8)
    args = (np.array([0], np.int64), np.array([7], np.uint32), np.array([[0, 0, 0, 4]], np.int64), (out,))
    copied = _cdr_copy.run(base, np.array([4, 20, 36], np.int64), 12, *args, np.array([16], np.int64), 0)
    assert copied == 0  # message 0's count is 0
    base[4:8] = base[36:40] = [7, 0, 0, 0]
    assert _cdr_copy.run(base, np.array([4, 20, 36], np.int64), 12, *args, np.array([16], np.int64), 0) == 3
    base[33] = 0  # message 2's header
    assert _cdr_copy.run(base, np.array([4, 20, 36], np.int64), 12, *args, np.array([16], np.int64), 0) == 2
    assert out[:4].tolist() == out[16:20].tolist() == [7, 0, 0, 0]


def test_uuids_that_share_a_sort_key_are_still_told_apart():
    from scenegrep.readers.ros.decoders import _uuid_text

    mix = 0x9E3779B97F4A7C15  # the key mixes the two words: (mix, 0) and (0, 1) share one
    words = np.array([[mix, 0], [0, 1], [mix, 0], [5, 5]], dtype="<u8")
    raw = words.view(np.uint8).reshape(4, 16)
    texts = _uuid_text(raw).strings()
    expected = [bytes(r).hex() for r in raw]
    assert [t.replace("-", "") for t in texts] == expected and texts[0] is texts[2]


@given(
    st.lists(st.lists(st.sampled_from([0.0, 0.5, 1.0, -np.inf, np.nan]), max_size=3), min_size=1, max_size=6),
    st.booleans(),
)
def test_the_best_row_per_item_is_the_highest_score_first_of_equal_ones(scores, shuffle):
    from scenegrep.readers.ros.cdr import Level
    from scenegrep.readers.ros.decoders import _best

    rows = [(item, rank, s) for item, row in enumerate(scores) for rank, s in enumerate(row)]
    if shuffle:
        rows = rows[1:] + rows[:1]
    parent = np.array([r[0] for r in rows], dtype=np.int64)
    level = Level(parent, np.array([r[1] for r in rows], dtype=np.int64), {"p": np.array([r[2] for r in rows])})
    expected = []
    for item in range(len(scores)):
        mine = [(i, r, s) for i, (p, r, s) in enumerate(rows) if p == item]
        ranked = sorted(mine, key=lambda t: (np.isnan(t[2]), -t[2] if not np.isnan(t[2]) else 0, t[1]))
        expected.append(ranked[0][0] if ranked else -1)
    assert _best(level, "p", len(scores)).tolist() == expected
