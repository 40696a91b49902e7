"""MCAP record bodies (https://mcap.dev/spec) into messages: the one parser of the offline bag
reader (:mod:`.ros.chunks`) and the live follower (:mod:`.mcap_follow`).

A stream is the magic ``89 4D 43 41 50 30 0D 0A``, then records of an opcode (uint8), a length
(uint64) and that many bytes (:data:`HEADER`); each reader frames the top-level records of its
own source and hands every body to :meth:`Records.messages`. The bodies read: Schema 0x03 (id
u16, name, encoding, data u32-prefixed), Channel 0x04 (id u16, schema id u16, topic, message
encoding, metadata), Message 0x05 (channel u16, sequence u32, log time u64, publish time u64,
data to the body's end), Chunk 0x06 (start, end u64, uncompressed size u64, crc u32,
compression string, records u64-prefixed: uncompressed, ``lz4`` or ``zstd``; the records
inside are framed like the top-level ones). Strings are a uint32 length and UTF-8 bytes; other
records are skipped; CRCs are not checked. Schema id 0 is "no schema" (name, encoding, data
empty). A chunk's messages are made by one C loop (:mod:`._mcap_index`), not a Python step each.

Bounds: every length is checked against its body before it is used; a record or a chunk's
uncompressed size over the reader's ``limit`` is refused before it is read or decompressed
(:func:`check_size`), and decompression never makes more than the stated size plus one byte.
Faults are :class:`McapFormatError` with a one-line text naming the record's kind and byte
offset (``Chunk record at byte 1234: ...``); the reader adds its input's name and context.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from typing import Any, NamedTuple

from . import _mcap_index

MAGIC = b"\x89MCAP0\r\n"
HEADER = struct.Struct("<BQ")
"""A record's opcode and body length."""
_MESSAGE = struct.Struct("<HIQQ")
_CHUNK = struct.Struct("<QQQI")

FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, DATA_END = 0x02, 0x03, 0x04, 0x05, 0x06, 0x0F
_NAMES = {0x01: "Header", FOOTER: "Footer", SCHEMA: "Schema", CHANNEL: "Channel", MESSAGE: "Message"}
_NAMES |= {CHUNK: "Chunk", DATA_END: "Data End"}


class RawMessage(NamedTuple):
    """One message as recorded: its channel's topic, its schema (name, encoding, definition bytes), its
    message encoding, its log time (ns, as the writer logged it) and its bytes (or a memoryview of
    them)."""

    topic: str
    schema_name: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str
    log_time: int
    data: bytes


class McapFormatError(ValueError):
    """An MCAP stream that cannot be read (truncated, corrupt or over a size limit); one line."""


def describe(offset: int, opcode: int | None, reason: str) -> str:
    """``reason`` prefixed with the record it is about (its kind, when known, and byte offset)."""
    kind = "" if opcode is None else f"{_NAMES.get(opcode, f'opcode 0x{opcode:02x}')} "
    return f"{kind}record at byte {offset}: {reason}"


def check_size(offset: int, opcode: int | None, size: int, limit: int) -> None:
    """McapFormatError when a record (or a chunk's records) of ``size`` bytes is over ``limit``."""
    if size > limit:
        raise McapFormatError(
            describe(offset, opcode, f"{size} bytes, more than the limit of {limit} bytes per record")
        )


class _Fault(ValueError):
    """A fault of one record's body, described without its place."""


def _string(body: memoryview, pos: int) -> tuple[str, int]:
    """The length-prefixed UTF-8 string at ``pos`` and the position after it."""
    if pos + 4 > len(body):
        raise _Fault("malformed (a string's length runs past its record's end)")
    (n,) = struct.unpack_from("<I", body, pos)
    if pos + 4 + n > len(body):
        raise _Fault("malformed (a string runs past its record's end)")
    try:
        return str(body[pos + 4 : pos + 4 + n], "utf-8"), pos + 4 + n
    except UnicodeDecodeError as exc:
        raise _Fault(f"malformed (a string not UTF-8: {exc.reason})") from None


def decompress(compression: str, raw: memoryview, size: int, zstd: Any = None) -> bytes:
    """A chunk's records: ``raw`` decompressed to exactly ``size`` bytes (never more made);
    McapFormatError (a bare reason) otherwise. ``zstd``: a ``zstandard.ZstdDecompressor`` to use
    (a stream's reader keeps one: making one per chunk costs its context's memory each time)."""
    try:
        if compression == "":
            data = bytes(raw)
        elif compression == "zstd":
            import zstandard

            stated = zstandard.frame_content_size(raw)
            if stated > size:
                raise McapFormatError(f"a zstd frame of {stated} bytes in a chunk of {size}")
            data = (zstd or zstandard.ZstdDecompressor()).decompress(raw, max_output_size=size)
        elif compression == "lz4":
            import lz4.frame

            data = lz4.frame.LZ4FrameDecompressor().decompress(raw, max_length=size + 1)
        else:
            raise McapFormatError(f"unsupported compression {compression!r} (lz4, zstd or none)")
    except McapFormatError:
        raise
    except Exception as exc:  # the libraries raise their own error types on corrupt frames
        raise McapFormatError(f"corrupt {compression} data ({exc})") from None
    if len(data) != size:
        raise McapFormatError(f"{len(data)} bytes of records where the chunk announces {size}")
    return data


class Records:
    """The schemas and channels of one stream so far, and its record bodies into messages. With
    ``views``, a message's ``data`` is a memoryview into its record (a chunk's decompressed
    records: one decompression per chunk, no copy per message), else bytes."""

    def __init__(self, limit: int, views: bool = False):
        self.limit = limit
        self.views = views
        self.schemas: dict[int, tuple[str, str, bytes]] = {0: ("", "", b"")}
        self.channels: dict[int, tuple[str, str, str, bytes, str]] = {}
        self._zstd: Any = None

    def messages(self, offset: int, opcode: int, body: memoryview) -> Iterator[RawMessage]:
        """The messages of the record at byte ``offset`` (a Message, or a Chunk's, in order),
        registering the schemas and channels it defines; other records give none."""
        for run in self.runs(offset, opcode, body):
            yield from run

    def runs(self, offset: int, opcode: int, body: memoryview) -> Iterator[list[RawMessage]]:
        """The messages of :meth:`messages` in runs (lists, none empty): a Message record's one,
        or a Chunk's between its definition records (one run for a chunk that defines nothing)."""
        if opcode == CHUNK:
            yield from self._chunk(offset, body)
        elif opcode in (MESSAGE, SCHEMA, CHANNEL):
            message = self._record(offset, opcode, body)
            if message is not None:
                yield [message]

    def _record(self, offset: int, opcode: int, body: memoryview) -> RawMessage | None:
        """The message of a Message record, or None having registered a Schema or Channel."""
        try:
            if opcode == MESSAGE:
                return self._message(body)
            if opcode == SCHEMA:
                self._schema(body)
            else:
                self._channel(body)
            return None
        except _Fault as exc:
            raise McapFormatError(describe(offset, opcode, str(exc))) from None

    def _message(self, body: memoryview) -> RawMessage:
        if len(body) < _MESSAGE.size:
            raise _Fault(f"malformed ({len(body)} bytes, fewer than a message's {_MESSAGE.size}-byte header)")
        channel_id, _, log_time, _ = _MESSAGE.unpack_from(body)
        channel = self.channels.get(channel_id)
        if channel is None:
            raise _Fault(f"log time {log_time} ns: channel {channel_id} was never declared")
        data = body[_MESSAGE.size :]
        return RawMessage(*channel, log_time, data if self.views else bytes(data))

    def _schema(self, body: memoryview) -> None:
        if len(body) < 2:
            raise _Fault("malformed (shorter than a schema id)")
        (schema_id,) = struct.unpack_from("<H", body)
        name, pos = _string(body, 2)
        encoding, pos = _string(body, pos)
        if pos + 4 > len(body):
            raise _Fault("malformed (the schema's data length runs past its record's end)")
        (n,) = struct.unpack_from("<I", body, pos)
        if pos + 4 + n > len(body):
            raise _Fault("malformed (the schema's data runs past its record's end)")
        self.schemas[schema_id] = (name, encoding, bytes(body[pos + 4 : pos + 4 + n]))

    def _channel(self, body: memoryview) -> None:
        if len(body) < 4:
            raise _Fault("malformed (shorter than a channel and schema id)")
        channel_id, schema_id = struct.unpack_from("<HH", body)
        topic, pos = _string(body, 4)
        encoding, _ = _string(body, pos)
        schema = self.schemas.get(schema_id)
        if schema is None:
            raise _Fault(f"topic {topic!r}: schema {schema_id} was never declared")
        self.channels[channel_id] = (topic, *schema, encoding)

    def _chunk(self, offset: int, body: memoryview) -> Iterator[list[RawMessage]]:
        """The messages of a Chunk record: runs of them made by one C loop (:mod:`._mcap_index`),
        which stops at each definition (read here) and at a bad message (named here)."""
        data = memoryview(self._records(offset, body))
        at = 0
        while True:
            try:
                found, at, opcode = _mcap_index.messages(data, at, self.channels, RawMessage, self.views)
            except ValueError as exc:
                reason, where = exc.args
                raise McapFormatError(describe(offset, CHUNK, f"{reason} at byte {where}")) from None
            if found:
                yield found
            if opcode < 0:
                return
            length = HEADER.unpack_from(data, at)[1]
            try:
                self._record(at, opcode, data[at + HEADER.size : at + HEADER.size + length])
            except McapFormatError as exc:
                raise McapFormatError(describe(offset, CHUNK, f"in its records, {exc}")) from None
            at += HEADER.size + length

    def _records(self, offset: int, body: memoryview) -> bytes:
        """A Chunk record's records, decompressed (its uncompressed size checked first)."""
        if len(body) < _CHUNK.size:
            raise McapFormatError(describe(offset, CHUNK, "malformed (shorter than a chunk's header)"))
        size = _CHUNK.unpack_from(body)[2]
        check_size(offset, CHUNK, size, self.limit)
        try:
            compression, pos = _string(body, _CHUNK.size)
            if pos + 8 > len(body):
                raise _Fault("malformed (the length of the chunk's records runs past its end)")
            (n,) = struct.unpack_from("<Q", body, pos)
            if pos + 8 + n > len(body):
                raise _Fault("malformed (the chunk's records run past its end)")
            if compression == "zstd" and self._zstd is None:
                import zstandard

                self._zstd = zstandard.ZstdDecompressor()
            return decompress(compression, body[pos + 8 : pos + 8 + n], size, self._zstd)
        except (_Fault, McapFormatError) as exc:
            raise McapFormatError(describe(offset, CHUNK, str(exc))) from None
