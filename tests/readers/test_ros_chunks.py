"""The offline MCAP reader (:mod:`scenegrep.readers.ros.chunks`) against mcap's own StreamReader
on random files (schemas and channels defined between messages, chunked or loose messages,
small chunks, every compression), and on damaged files: a cut anywhere, a record length or a
chunk's uncompressed size made wrong, is a one-line UserError naming the last message read."""

from __future__ import annotations

import contextlib
import io
import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.records import Chunk
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from scenegrep.errors import UserError
from scenegrep.readers.ros.bag import messages as bag_stream
from scenegrep.readers.ros.chunks import McapFormatError, mcap_messages

LIMIT = 1 << 24
COMPRESSIONS = [CompressionType.NONE, CompressionType.LZ4, CompressionType.ZSTD]

message = st.tuples(st.integers(0, 2), st.integers(0, 2**40), st.binary(max_size=300))


def _write(items, compression, chunk_size: int, chunked: bool) -> bytes:
    """An MCAP file of ``items`` (topic number, log time, data); each topic's schema and channel
    registered when its first message comes."""
    out = io.BytesIO()
    writer = Writer(out, chunk_size=chunk_size, compression=compression, use_chunking=chunked)
    writer.start("ros2", "test")
    channels: dict[int, int] = {}
    for topic, log_time, data in items:
        if topic not in channels:
            schema = writer.register_schema(f"pkg/msg/T{topic}", "ros2msg", f"int32 x{topic}".encode())
            channels[topic] = writer.register_channel(f"/t{topic}", "cdr", schema)
        writer.add_message(channels[topic], log_time=log_time, data=data, publish_time=log_time)
    writer.finish()
    return out.getvalue()


def _reference(data: bytes) -> list[tuple]:
    """The messages as mcap's StreamReader reads them."""
    return list(_reference_iter(data))


def _reference_iter(data: bytes):
    schemas, channels = {}, {}
    for record in StreamReader(io.BytesIO(data)).records:
        kind = type(record).__name__
        if kind == "Schema":
            schemas[record.id] = record
        elif kind == "Channel":
            channels[record.id] = record
        elif kind == "Message":
            channel = channels[record.channel_id]
            schema = schemas[channel.schema_id]
            yield (channel.topic, schema.name, schema.encoding, schema.data, channel.message_encoding) + (
                record.log_time,
                bytes(record.data),
            )


@settings(max_examples=40, deadline=None)
@given(
    st.lists(message, max_size=40),
    st.sampled_from(COMPRESSIONS),
    st.integers(1, 2000),
    st.booleans(),
    st.booleans(),
)
def test_the_messages_are_those_mcap_reads(items, compression, chunk_size, chunked, views):
    data = _write(items, compression, chunk_size, chunked)
    read = [tuple(m[:-1]) + (bytes(m.data),) for m in mcap_messages(io.BytesIO(data), LIMIT, views)]
    assert read == _reference(data)
    if views and read:
        assert all(isinstance(m.data, memoryview) for m in mcap_messages(io.BytesIO(data), LIMIT, True))


ITEMS = [(k % 3, 1_000 * k, bytes([k]) * (10 + k)) for k in range(30)]


@pytest.fixture(scope="module", params=COMPRESSIONS, ids=lambda c: c.name)
def good(request) -> bytes:
    return _write(ITEMS, request.param, 200, True)


def _read(data: bytes) -> list:
    return list(bag_stream(io.BytesIO(data), "f.mcap", True))


def _one_line(data: bytes) -> str:
    """The error reading ``data``; it names the last message read before the fault (the
    messages before it read as mcap reads them)."""
    read = []
    with pytest.raises(UserError) as error:
        for m in bag_stream(io.BytesIO(data), "f.mcap", True):
            read.append(tuple(m[:-1]) + (bytes(m.data),))
    line = error.value.one_line()
    assert "\n" not in line and "truncated or corrupt" in line and "f.mcap" in line
    assert read == [m for m in _reference_prefix(data)][: len(read)]
    if read:
        assert f"after topic {read[-1][0]}, message at log time {read[-1][5]} ns:" in line
    else:
        assert "at its start" in line
    return line


def _reference_prefix(data: bytes) -> list[tuple]:
    """The messages mcap reads from a damaged file before its own error."""
    out: list[tuple] = []
    with contextlib.suppress(Exception):  # mcap's own error types
        for message in _reference_iter(data):
            out.append(message)
    return out


@settings(max_examples=30, deadline=None)
@given(st.floats(0, 1, exclude_max=True))
def test_a_cut_file_is_a_one_line_error_naming_the_last_message(good, where):
    _one_line(good[: int(len(good) * where)])


def _chunks(data: bytes) -> list[int]:
    """Byte offsets of the Chunk records of a file."""
    offsets, pos = [], 8
    while pos + 9 <= len(data):
        op, length = struct.unpack_from("<BQ", data, pos)
        if op == 0x06:
            offsets.append(pos)
        pos += 9 + length
    return offsets


def test_a_bad_record_length_is_an_error(good):
    second = _chunks(good)[1]
    for length in (2**62, 3, len(good)):
        bad = good[: second + 1] + struct.pack("<Q", length) + good[second + 9 :]
        _one_line(bad)
    line = _one_line(good[: second + 1] + struct.pack("<Q", 2**62) + good[second + 9 :])
    assert "4611686018427387904 bytes, more than the limit" in line  # refused before it is read


@pytest.mark.parametrize("size", [2**40, 1 << 25, 7])
def test_a_wrong_uncompressed_size_is_an_error(good, size):
    second = _chunks(good)[1]
    # Chunk: opcode, length, start u64, end u64, uncompressed size u64
    bad = good[: second + 25] + struct.pack("<Q", size) + good[second + 33 :]
    line = _one_line(bad)
    assert "Chunk record at byte" in line


def test_a_record_running_past_its_chunk_is_an_error():
    data = _write(ITEMS, CompressionType.NONE, 200, True)
    chunk = _chunks(data)[1]
    head = StreamReader(io.BytesIO(data[chunk:]), skip_magic=True, emit_chunks=True).records
    record = next(r for r in head if isinstance(r, Chunk))
    inner = data.index(record.data, chunk)  # its first record's length, inside the chunk
    bad = data[: inner + 1] + struct.pack("<Q", len(record.data)) + data[inner + 9 :]
    assert "past the end of its chunk" in _one_line(bad)


def test_a_message_on_an_undefined_channel_and_no_magic():
    with pytest.raises(McapFormatError, match="no MCAP magic"):
        list(mcap_messages(io.BytesIO(b"not an mcap file"), LIMIT))
    data = _write(ITEMS[:1], CompressionType.NONE, 200, False)
    schema_at = data.index(b"pkg/msg/T0") - 4 - 2 - 9  # the Schema record's opcode
    (length,) = struct.unpack_from("<Q", data, schema_at + 1)
    channel_at = schema_at + 9 + length
    # the channel record renamed to an unknown opcode: the message's channel is never defined
    bad = data[:channel_at] + b"\x7f" + data[channel_at + 1 :]
    assert "channel 1 was never declared" in _one_line(bad)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), min_size=1, max_size=4))
def test_flipped_bytes_are_messages_or_a_one_line_error(good, flips):
    bad = bytearray(good)
    for where, value in flips:
        bad[int(len(bad) * where)] = value
    try:
        for m in bag_stream(io.BytesIO(bytes(bad)), "f.mcap", True):
            assert isinstance(m.data, memoryview)
    except UserError as error:
        assert "\n" not in error.one_line()


def test_a_message_in_a_chunk_on_an_undeclared_channel_is_an_error_after_the_messages_before_it():
    data = _write(ITEMS, CompressionType.NONE, 10_000, True)  # one chunk
    seventh = struct.pack("<HIQQ", 1, 0, 6_000, 6_000)  # the 7th message: channel 1 (topic /t0), log time 6000
    at = data.index(seventh)
    bad = data[:at] + struct.pack("<H", 9) + data[at + 2 :]
    line = _one_line(bad)
    assert "after topic /t2, message at log time 5000 ns: Chunk record at byte" in line
    # the chunk's records: after its header (start, end, size u64, crc u32), compression "" and their length
    records = _chunks(bad)[0] + 9 + 28 + 4 + 8
    inner = at - 9 - records  # the Message record's byte offset among the chunk's records
    assert line.endswith(
        f"in its records, Message record at byte {inner}: log time 6000 ns: channel 9 was never declared"
    )
