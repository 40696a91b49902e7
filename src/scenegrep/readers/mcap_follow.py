"""Raw messages of an MCAP stream while it is being written: a growing file (``--follow``) or standard input.

:func:`follow_mcap` yields :class:`RawMessage` tuples (topic, schema name, encoding and data, message
encoding, log time in ns, payload) in the stream's record order, each as soon as the record that carries
it has wholly arrived: a Message record, or for messages inside a Chunk record the whole chunk (a
live writer that wants each message seen at once writes unchunked, e.g. ``noChunking: true`` in the
storage configuration of ``ros2 bag record -s mcap``, or small chunks).

* Records are framed by their own prefix (opcode: 1 byte, length: 8 bytes, little-endian) and parsed
  only once all their bytes are there, so a half-written record is never read; a file is read from
  the start and polled every ``poll`` seconds for appended bytes.
* The stream ends at its Data End record (the summary section and footer after it only index what
  was read) or a Footer; at the end of standard input; or, following a file, after ``idle_timeout``
  seconds without growth (``None``: wait for ever; Ctrl-C or SIGTERM then stop the caller). Input that
  ends inside a record is an error (a truncated stream), one that ends between records is not (a
  writer that was stopped before its summary). A followed file that shrinks is an error.
* Memory is bounded: one record's bytes at a time (plus one read block), a chunk's decompressed
  records, and the schemas and channels seen. A record (or a chunk's uncompressed data) longer than
  ``max_record`` bytes is refused before it is read, so a corrupt length cannot exhaust memory.
  Chunks may be uncompressed, ``lz4`` or ``zstd``; CRCs are not checked.
* Errors (not MCAP, truncated, malformed records, unknown compression, a message on a channel never
  declared) are :class:`~scenegrep.errors.UserError` naming the input and the record's byte offset.

:meth:`MessageStream.batches` groups the messages that had arrived together (one at a time while the
reader keeps up, in bulk while it catches up). :attr:`MessageStream.arrival` is the
:func:`time.perf_counter` time at which the last message handed out was read: the start of a
frame's online latency.
"""

from __future__ import annotations

import io
import os
import struct
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO, NamedTuple

from ..errors import UserError, at

MAGIC = b"\x89MCAP0\r\n"
POLL_SECONDS = 0.01
"""Default poll interval of a followed file: 10 ms, a tenth of the 100 ms latency budget, at the cost
of ~100 empty reads a second while the writer is idle."""
MAX_RECORD_BYTES = 256 * 2**20
READ_BLOCK = 2**20
BATCH_MESSAGES = 4096
"""The most messages :meth:`MessageStream.batches` hands out together."""

_HEADER = struct.Struct("<BQ")
_MESSAGE = struct.Struct("<HIQQ")
_SCHEMA = 0x03
_CHANNEL = 0x04
_MESSAGE_OP = 0x05
_CHUNK = 0x06
_DATA_END = 0x0F
_FOOTER = 0x02
_NAMES = {0x01: "Header", _FOOTER: "Footer", _SCHEMA: "Schema", _CHANNEL: "Channel", _MESSAGE_OP: "Message"}
_NAMES |= {_CHUNK: "Chunk", _DATA_END: "Data End"}


class RawMessage(NamedTuple):
    """One message as recorded: its channel's topic, its schema (name, encoding, definition bytes), its
    message encoding, its log time (ns, as the writer logged it) and its bytes."""

    topic: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str
    log_time: int
    data: bytes


@dataclass(frozen=True)
class FollowOptions:
    """How a stream is read: ``poll`` and ``idle_timeout`` in seconds (files only), ``max_record`` in bytes."""

    poll: float = POLL_SECONDS
    idle_timeout: float | None = None
    max_record: int = MAX_RECORD_BYTES


class _Source:
    """Bytes as they arrive: :meth:`read` returns some bytes, ``b""`` (nothing yet: ask again) or
    ``None`` (the input ended)."""

    def __init__(self, stream: BinaryIO, options: FollowOptions, follow: bool, name: str):
        self.stream = stream
        self.options = options
        self.follow = follow
        self.name = name
        self.grown = time.monotonic()
        self.position = 0
        self.caught_up = False
        """Whether the last read got less than it asked for: nothing more had arrived then."""

    def read(self, size: int) -> bytes | None:
        data = self.stream.read(size) if self.follow else self.stream.read1(size)  # type: ignore[attr-defined]
        self.caught_up = len(data) < size
        if data:
            self.grown = time.monotonic()
            self.position += len(data)
            return data
        if not self.follow:
            return None
        if os.fstat(self.stream.fileno()).st_size < self.position:
            raise UserError(f"the file shrank to fewer than the {self.position} bytes read (truncated?)", at(self.name))
        idle = self.options.idle_timeout
        if idle is not None and time.monotonic() - self.grown >= idle:
            return None
        time.sleep(self.options.poll)
        return b""


class MessageStream:
    """The messages of one MCAP stream (iterate once); see the module docstring."""

    def __init__(self, path: str, options: FollowOptions = FollowOptions(), stdin: BinaryIO | None = None):
        self.path = path
        self.stdin = stdin
        self.name = "<stdin>" if path == "-" else path
        self.options = options
        self.arrival = time.perf_counter()
        self._schemas: dict[int, tuple[str, str, bytes]] = {0: ("", "", b"")}
        self._channels: dict[int, tuple[str, str, int]] = {}

    def __iter__(self) -> Iterator[RawMessage]:
        return (message for message in self._items() if message is not None)

    def batches(self, limit: int = BATCH_MESSAGES) -> Iterator[list[RawMessage]]:
        """The messages in lists, each handed out once the reader has caught up with the input (the
        next record has not wholly arrived yet) or holds ``limit`` messages: one message at a time
        while the reader keeps up with a writer, in bulk while it catches up on a backlog."""
        batch: list[RawMessage] = []
        for message in self._items():
            if message is not None:
                batch.append(message)
            if batch and (message is None or len(batch) >= limit):
                yield batch
                batch = []
        if batch:
            yield batch

    def _items(self) -> Iterator[RawMessage | None]:
        """The messages, and None whenever the reader has caught up with the input."""
        if self.path == "-":
            yield from self._messages(_Source(self.stdin or sys.stdin.buffer, self.options, False, self.name))
            return
        try:
            with open(self.path, "rb", buffering=0) as stream:
                yield from self._messages(_Source(stream, self.options, True, self.name))
        except OSError as exc:
            raise UserError(f"cannot read: {exc.strerror}", at(self.path)) from None

    def _messages(self, source: _Source) -> Iterator[RawMessage | None]:
        for offset, opcode, body in self._records(source):
            if body is None:
                yield None
            elif opcode in (_DATA_END, _FOOTER):
                return
            else:
                for message in self._decode(offset, opcode, body):
                    self.arrival = time.perf_counter()
                    yield message

    def _records(self, source: _Source) -> Iterator[tuple[int, int, memoryview | None]]:
        """(byte offset, opcode, body) of each whole top-level record after the magic; the body is
        None (a mark, no record) when the next record has not wholly arrived and the input had no
        more bytes at the last read."""
        buffer = bytearray()
        offset = 0

        def fill(size: int) -> bool:
            while len(buffer) < size:
                data = source.read(max(size - len(buffer), READ_BLOCK))
                if data is None:
                    return False
                buffer.extend(data)
            return True

        if not fill(len(MAGIC)) or buffer[: len(MAGIC)] != MAGIC:
            raise UserError("not an MCAP stream (no MCAP magic at its start)", at(self.name))
        del buffer[: len(MAGIC)]
        offset = len(MAGIC)
        while True:
            whole = len(buffer) >= _HEADER.size and len(buffer) >= _HEADER.size + _HEADER.unpack_from(buffer)[1]
            if source.caught_up and not whole:
                yield offset, 0, None
            if not fill(_HEADER.size):
                if buffer:
                    raise self._error(offset, None, "the stream ends inside a record's header")
                return
            opcode, length = _HEADER.unpack_from(buffer)
            self._check_size(offset, opcode, length)
            if not fill(_HEADER.size + length):
                raise self._error(offset, opcode, f"truncated: {length} bytes announced, {len(buffer) - 9} arrived")
            end = _HEADER.size + length
            yield offset, opcode, memoryview(bytes(buffer[_HEADER.size : end]))
            del buffer[:end]
            offset += end

    def _check_size(self, offset: int, opcode: int | None, size: int) -> None:
        if size > self.options.max_record:
            limit = self.options.max_record
            raise self._error(offset, opcode, f"{size} bytes, more than the limit of {limit} bytes per record")

    def _error(self, offset: int, opcode: int | None, message: str) -> UserError:
        kind = "" if opcode is None else f"{_NAMES.get(opcode, f'opcode 0x{opcode:02x}')} "
        return UserError(f"{kind}record at byte {offset}: {message}", at(self.name))

    def _decode(self, offset: int, opcode: int, body: memoryview) -> list[RawMessage]:
        """The messages of one record (a Message, or a Chunk's), registering its schemas and channels."""
        try:
            if opcode == _MESSAGE_OP:
                return [self._message(offset, body)]
            if opcode == _SCHEMA:
                self._schema(body)
            elif opcode == _CHANNEL:
                self._channel(offset, body)
            elif opcode == _CHUNK:
                return self._chunk(offset, body)
            return []
        except (struct.error, UnicodeDecodeError, IndexError) as exc:
            raise self._error(offset, opcode, f"malformed ({exc})") from None

    def _message(self, offset: int, body: memoryview) -> RawMessage:
        channel_id, _, log_time, _ = _MESSAGE.unpack_from(body)
        if channel_id not in self._channels:
            raise self._error(offset, _MESSAGE_OP, f"log time {log_time} ns: channel {channel_id} was never declared")
        topic, encoding, schema_id = self._channels[channel_id]
        return RawMessage(topic, *self._schemas[schema_id], encoding, log_time, bytes(body[_MESSAGE.size :]))

    def _schema(self, body: memoryview) -> None:
        (schema_id,) = struct.unpack_from("<H", body)
        name, at_encoding = _string(body, 2)
        encoding, at_data = _string(body, at_encoding)
        (size,) = struct.unpack_from("<I", body, at_data)
        data = bytes(body[at_data + 4 : at_data + 4 + size])
        if len(data) != size:
            raise struct.error("schema data shorter than its length")
        self._schemas[schema_id] = (name, encoding, data)

    def _channel(self, offset: int, body: memoryview) -> None:
        channel_id, schema_id = struct.unpack_from("<HH", body)
        topic, at_encoding = _string(body, 4)
        encoding, _ = _string(body, at_encoding)
        if schema_id not in self._schemas:
            raise self._error(offset, _CHANNEL, f"topic {topic!r}: schema {schema_id} was never declared")
        self._channels[channel_id] = (topic, encoding, schema_id)

    def _chunk(self, offset: int, body: memoryview) -> list[RawMessage]:
        size = struct.unpack_from("<Q", body, 16)[0]
        self._check_size(offset, _CHUNK, size)
        compression, at_data = _string(body, 28)
        (length,) = struct.unpack_from("<Q", body, at_data)
        data = _decompress(body[at_data + 8 : at_data + 8 + length], compression, size, self._error, offset)
        messages: list[RawMessage] = []
        position = 0
        while position < len(data):
            opcode, length = _HEADER.unpack_from(data, position)
            start = position + _HEADER.size
            if start + length > len(data):
                raise self._error(offset, _CHUNK, f"a record inside runs past the chunk's end at byte {position}")
            messages.extend(self._decode(offset, opcode, data[start : start + length]))
            position = start + length
        return messages


def _string(body: memoryview, position: int) -> tuple[str, int]:
    """The length-prefixed UTF-8 string at ``position`` and the position after it."""
    (size,) = struct.unpack_from("<I", body, position)
    raw = body[position + 4 : position + 4 + size]
    if len(raw) != size:
        raise struct.error("a string runs past its record's end")
    return str(raw, "utf-8"), position + 4 + size


def _decompress(data: memoryview, compression: str, size: int, error, offset: int) -> memoryview:
    """A chunk's records: ``data`` decompressed to exactly ``size`` bytes, never more read."""
    if compression == "":
        raw = bytes(data)
    elif compression in ("lz4", "zstd"):
        reader = _decompressor(compression, io.BytesIO(data))
        parts: list[bytes] = []
        wanted = size + 1
        try:
            while wanted and (part := reader.read(wanted)):
                parts.append(part)
                wanted -= len(part)
        except Exception as exc:  # the libraries raise their own error types on corrupt frames
            raise error(offset, _CHUNK, f"corrupt {compression} data ({exc})") from None
        raw = b"".join(parts)
    else:
        raise error(offset, _CHUNK, f"unsupported compression {compression!r} (lz4, zstd or none)")
    if len(raw) != size:
        raise error(offset, _CHUNK, f"{len(raw)} bytes of records where the chunk announces {size}")
    return memoryview(raw)


def _decompressor(compression: str, stream: BinaryIO) -> BinaryIO:
    if compression == "lz4":
        import lz4.frame

        return lz4.frame.LZ4FrameFile(stream, mode="rb")
    import zstandard

    return zstandard.ZstdDecompressor().stream_reader(stream)


class _Replay(io.RawIOBase):
    """A stream whose first bytes were already read: ``head`` then the rest of ``stream``."""

    def __init__(self, head: bytes, stream: BinaryIO):
        self.head = head
        self.stream = stream

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        if self.head:
            size = min(len(buffer), len(self.head))
            buffer[:size], self.head = self.head[:size], self.head[size:]
            return size
        read = getattr(self.stream, "read1", self.stream.read)
        data = read(len(buffer))
        buffer[: len(data)] = data
        return len(data)


def sniff_mcap(stream: BinaryIO) -> tuple[bool, BinaryIO]:
    """Whether ``stream`` (standard input, say) starts with MCAP's magic bytes, and the stream
    with nothing consumed (the bytes read to tell are replayed). Reads at most the magic's 8 bytes,
    each read returning what has arrived, so a live writer is not waited for beyond them."""
    read = getattr(stream, "read1", stream.read)
    head = b""
    while len(head) < len(MAGIC) and (part := read(len(MAGIC) - len(head))):
        head += part
    return head == MAGIC, io.BufferedReader(_Replay(head, stream))


def follow_mcap(
    path: str | Path, options: FollowOptions = FollowOptions(), stdin: BinaryIO | None = None
) -> MessageStream:
    """The messages of the MCAP stream at ``path`` (``-``: ``stdin``, by default standard input) as
    they are written."""
    return MessageStream(str(path), options, stdin)
