"""Following an MCAP stream as it is written (:mod:`scenegrep.readers.mcap_follow`): the messages the
mcap library's own reader reads from the finished file, from a file that grows in arbitrary pieces
or from standard input cut anywhere; never a half-written record; bounded records; one-line errors."""

from __future__ import annotations

import io
import struct
import sys
import threading
import time
from types import SimpleNamespace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from scenegrep.errors import UserError
from scenegrep.readers.mcap_follow import MAGIC, FollowOptions, RawMessage, follow_mcap, sniff_mcap

QUICK = FollowOptions(poll=0.001, idle_timeout=0.3)


def mcap_bytes(count: int = 40, compression: str = "none", chunk_size: int = 300) -> bytes:
    """An MCAP file: ``count`` messages alternating on two topics (one without a schema)."""
    output = io.BytesIO()
    kinds = {"none": CompressionType.NONE, "lz4": CompressionType.LZ4, "zstd": CompressionType.ZSTD}
    writer = Writer(
        output,
        chunk_size=chunk_size,
        compression=kinds.get(compression, CompressionType.NONE),
        use_chunking=compression != "unchunked",
    )
    writer.start("ros2", "test")
    schema = writer.register_schema("pkg/msg/Thing", "ros2msg", b"int32 x")
    channels = [
        writer.register_channel("/things", "cdr", schema),
        writer.register_channel("/notes", "json", 0),
    ]
    for k in range(count):
        payload = bytes([k % 256]) * (k % 7) + f"#{k}".encode()
        writer.add_message(channels[k % 2], log_time=1_000_000 * k, data=payload, publish_time=1_000_000 * k)
    writer.finish()
    return output.getvalue()


def reference(data: bytes) -> list[RawMessage]:
    """The messages as the mcap library reads the finished file."""
    return [
        RawMessage(
            channel.topic,
            schema.name if schema else "",
            schema.encoding if schema else "",
            schema.data if schema else b"",
            channel.message_encoding,
            message.log_time,
            message.data,
        )
        for schema, channel, message in make_reader(io.BytesIO(data)).iter_messages(log_time_order=False)
    ]


class _Pieces:
    """Standard input that hands out the bytes in the given pieces, one per read."""

    def __init__(self, data: bytes, cuts: list[int]):
        edges = [0, *sorted(set(cuts)), len(data)]
        self.pieces = [data[a:b] for a, b in zip(edges, edges[1:]) if b > a]

    def read1(self, size: int = -1) -> bytes:
        return self.pieces.pop(0) if self.pieces else b""


def from_stdin(monkeypatch, data: bytes, cuts: list[int], options: FollowOptions = QUICK) -> list[RawMessage]:
    monkeypatch.setattr(sys, "stdin", SimpleNamespace(buffer=_Pieces(data, cuts)))
    return list(follow_mcap("-", options))


@pytest.mark.parametrize("compression", ["unchunked", "none", "lz4", "zstd"])
def test_a_finished_file_gives_the_libraries_messages_and_ends_at_its_data_end(tmp_path, compression):
    data = mcap_bytes(compression=compression)
    (tmp_path / "a.mcap").write_bytes(data)
    started = time.monotonic()
    messages = list(follow_mcap(tmp_path / "a.mcap", FollowOptions(idle_timeout=None)))
    assert time.monotonic() - started < 1.0  # ended by the Data End record, not by waiting
    assert messages == reference(data) and len(messages) == 40


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(["unchunked", "lz4"]), st.lists(st.integers(0, 4000), max_size=30))
def test_standard_input_cut_anywhere_gives_the_same_messages(monkeypatch_session, compression, cuts):
    """Messages one by one, or in batches (one per piece that completes records, at most 7): the same."""
    data = mcap_bytes(compression=compression)
    assert from_stdin(monkeypatch_session, data, cuts) == reference(data)
    monkeypatch_session.setattr(sys, "stdin", SimpleNamespace(buffer=_Pieces(data, cuts)))
    batches = list(follow_mcap("-", QUICK).batches(limit=7))
    assert sum(batches, []) == reference(data) and all(0 < len(batch) <= 7 for batch in batches)


@pytest.fixture(scope="module")
def monkeypatch_session():
    with pytest.MonkeyPatch.context() as patch:
        yield patch


def grow(path, data: bytes, cuts: list[int], pause: float, written: list) -> threading.Thread:
    """Append ``data`` to ``path`` piece by piece from another thread; ``written`` gets each piece's end."""

    def run() -> None:
        edges = [0, *cuts, len(data)]
        with open(path, "ab", buffering=0) as file:
            for a, b in zip(edges, edges[1:]):
                file.write(data[a:b])
                written.append((b, time.perf_counter()))
                time.sleep(pause)

    thread = threading.Thread(target=run)
    thread.start()
    return thread


def test_a_growing_file_yields_each_message_once_its_record_is_whole(tmp_path):
    """Pieces cut inside headers and bodies: a message comes out only after its record's last byte
    was written, and within a few poll intervals of it."""
    data = mcap_bytes(count=12, compression="unchunked")
    path = tmp_path / "live.mcap"
    path.write_bytes(b"")
    ends = record_ends(data)
    cuts = sorted({end - 3 for end in ends} | {end + 5 for end in ends if end + 5 < len(data)})
    written: list = []
    thread = grow(path, data, cuts, 0.01, written)
    stream = follow_mcap(path, QUICK)
    seen = [(message, stream.arrival) for message in stream]
    thread.join()
    assert [message for message, _ in seen] == reference(data)
    message_ends = [end for end, opcode in ends.items() if opcode == 0x05]
    for (_, arrival), end in zip(seen, message_ends):
        last_piece = min(time for stop, time in written if stop >= end)
        assert last_piece <= arrival < last_piece + 0.2


def record_ends(data: bytes) -> dict[int, int]:
    """Top-level records of an MCAP file: end offset -> opcode."""
    ends = {}
    position = len(MAGIC)
    while position + 9 <= len(data) - len(MAGIC):
        opcode, length = struct.unpack_from("<BQ", data, position)
        position += 9 + length
        ends[position] = opcode
    return ends


def test_a_half_written_record_is_never_read(tmp_path):
    data = mcap_bytes(count=6, compression="unchunked")
    last_message = max(end for end, opcode in record_ends(data).items() if opcode == 0x05)
    path = tmp_path / "half.mcap"
    path.write_bytes(data[: last_message - 1])
    seen = []
    with pytest.raises(UserError, match=r"Message record at byte \d+: truncated: \d+ bytes announced"):
        seen.extend(follow_mcap(path, QUICK))
    assert seen == reference(data)[:5]


def test_a_writer_stopped_between_records_ends_at_the_idle_timeout(tmp_path):
    data = mcap_bytes(count=6, compression="unchunked")
    last_message = max(end for end, opcode in record_ends(data).items() if opcode == 0x05)
    path = tmp_path / "stopped.mcap"
    path.write_bytes(data[:last_message])
    started = time.monotonic()
    assert list(follow_mcap(path, FollowOptions(idle_timeout=0.2))) == reference(data)
    assert 0.2 <= time.monotonic() - started < 1.5


def patch_record(data: bytes, opcode: int, change) -> bytes:
    """``data`` with the body of its first record of ``opcode`` replaced by ``change(body)``."""
    position = len(MAGIC)
    while True:
        code, length = struct.unpack_from("<BQ", data, position)
        if code == opcode:
            body = change(data[position + 9 : position + 9 + length])
            head = struct.pack("<BQ", code, len(body))
            return data[:position] + head + body + data[position + 9 + length :]
        position += 9 + length


def chunk_with_compression(name: bytes):
    def change(body: bytes) -> bytes:
        (size,) = struct.unpack_from("<I", body, 28)
        return body[:28] + struct.pack("<I", len(name)) + name + body[32 + size :]

    return change


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"", "not an MCAP stream"),
        (b"PAR1....", "not an MCAP stream"),
        (MAGIC + b"\x05\x01", r"record at byte 8: the stream ends inside a record's header"),
        (
            MAGIC + struct.pack("<BQ", 0x05, 2**40),
            r"Message record at byte 8: 1099511627776 bytes, more than the limit",
        ),
        (
            patch_record(mcap_bytes(4, "lz4"), 0x06, chunk_with_compression(b"brotli")),
            "unsupported compression 'brotli'",
        ),
        (patch_record(mcap_bytes(4, "lz4"), 0x06, lambda b: b[:43] + b"\x00" * 4 + b[47:]), "corrupt lz4 data"),
        (patch_record(mcap_bytes(4, "zstd"), 0x06, lambda b: b[:-6] + b"\xff" * 6), "Chunk record at byte"),
        (patch_record(mcap_bytes(4, "unchunked"), 0x04, lambda b: b[:6]), r"Channel record at byte \d+: malformed"),
        (patch_record(mcap_bytes(4, "unchunked"), 0x05, lambda b: b"\x09\x00" + b[2:]), "channel 9 was never declared"),
        (patch_record(mcap_bytes(4, "unchunked"), 0x04, lambda b: b[:2] + b"\x07\x00" + b[4:]), "schema 7 was never"),
    ],
)
def test_malformed_streams_are_one_line_errors(monkeypatch, data, message):
    with pytest.raises(UserError, match=message) as error:
        from_stdin(monkeypatch, data, [])
    assert error.value.one_line().startswith("<stdin>: ") and "\n" not in error.value.one_line()


def test_a_chunk_announcing_more_than_the_limit_is_refused_before_it_is_decompressed(monkeypatch):
    data = patch_record(mcap_bytes(4, "zstd"), 0x06, lambda b: b[:16] + struct.pack("<Q", 2**50) + b[24:])
    with pytest.raises(UserError, match=r"Chunk record at byte \d+: 1125899906842624 bytes, more than the limit"):
        from_stdin(monkeypatch, data, [])


def test_a_record_over_a_chosen_limit_is_refused(monkeypatch):
    data = mcap_bytes(4, "unchunked")
    with pytest.raises(UserError, match="more than the limit of 12 bytes per record"):
        from_stdin(monkeypatch, data, [], FollowOptions(max_record=12))


def test_a_missing_file_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match=r"nothing\.mcap: cannot read: No such file"):
        list(follow_mcap(tmp_path / "nothing.mcap", QUICK))


def test_a_followed_file_that_shrinks_is_an_error(tmp_path):
    data = mcap_bytes(count=6, compression="unchunked")
    last_message = max(end for end, opcode in record_ends(data).items() if opcode == 0x05)
    path = tmp_path / "rotated.mcap"
    path.write_bytes(data[:last_message])
    stream = iter(follow_mcap(path, QUICK))
    next(stream)
    path.write_bytes(data[:100])
    with pytest.raises(UserError, match=r"rotated\.mcap: the file shrank to fewer than the \d+ bytes read"):
        list(stream)


def test_batches_group_what_had_arrived_together(monkeypatch):
    """Standard input cut at every record's end, read piece by piece: each batch is the messages of
    one piece (a caught-up reader gets each message alone); given whole, the messages in batches of
    at most ``limit``."""
    data = mcap_bytes(count=10, compression="unchunked")
    cuts = list(record_ends(data))
    monkeypatch.setattr(sys, "stdin", SimpleNamespace(buffer=_Pieces(data, cuts)))
    assert list(follow_mcap("-", QUICK).batches()) == [[message] for message in reference(data)]
    monkeypatch.setattr(sys, "stdin", SimpleNamespace(buffer=_Pieces(data, [])))
    batches = list(follow_mcap("-", QUICK).batches(limit=4))
    assert [len(batch) for batch in batches] == [4, 4, 2] and sum(batches, []) == reference(data)


class _Trickle(io.RawIOBase):
    """A stream that hands out at most ``step`` bytes per read, as a pipe from a live writer may."""

    def __init__(self, data: bytes, step: int):
        self.data, self.step = data, step

    def readable(self) -> bool:
        return True

    def readinto(self, buffer) -> int:
        size = min(len(buffer), self.step, len(self.data))
        buffer[:size], self.data = self.data[:size], self.data[size:]
        return size


@settings(max_examples=60)
@given(st.one_of(st.binary(max_size=20), st.binary(max_size=12).map(lambda b: MAGIC + b)), st.integers(1, 9))
def test_sniffing_mcap_consumes_nothing(data, step):
    is_mcap, stream = sniff_mcap(_Trickle(data, step))
    assert is_mcap == data.startswith(MAGIC)
    assert stream.read() == data
