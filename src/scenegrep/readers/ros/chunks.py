"""The messages of an MCAP file read offline, each a view into its decompressed chunk (no copy).

Record framing (https://mcap.dev/spec): the magic ``89 4D 43 41 50 30 0D 0A``, then records of
an opcode (uint8), a length (uint64) and that many bytes, up to the Footer and the magic again.
Schema 0x03 (id u16, name, encoding, data u32-prefixed), Channel 0x04 (id u16, schema id u16,
topic, message encoding, metadata), Message 0x05 (channel u16, sequence u32, log time u64,
publish time u64, data to the record's end), Chunk 0x06 (start, end u64, uncompressed size
u64, crc u32, compression string, records u64-prefixed: uncompressed, ``lz4`` or ``zstd``).
Strings are a uint32 length and UTF-8 bytes; other records are skipped; CRCs are not checked.

:func:`mcap_messages` yields :class:`RawMessage` tuples; with ``views``, their ``data`` is a
``memoryview`` into the decompressed chunk that holds it (one decompression per chunk, one
Python step per record, no copy), so a batch decoder can read many messages of a chunk with one strided view
(:mod:`.cdr_layout`). Every length is checked before it is used: a record running past its
file or chunk, a chunk or record over ``limit`` bytes or a chunk whose records do not
decompress to exactly its stated size is an :class:`McapFormatError` (the caller names the
last message read).
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from typing import BinaryIO

from .messages import RawMessage

MAGIC = b"\x89MCAP0\r\n"
_RECORD = struct.Struct("<BQ")
_MESSAGE = struct.Struct("<HIQQ")
_CHUNK = struct.Struct("<QQQI")
_SCHEMA, _CHANNEL, _MESSAGE_OP, _CHUNK_OP, _FOOTER = 0x03, 0x04, 0x05, 0x06, 0x02


class McapFormatError(ValueError):
    """An MCAP file that cannot be read (truncated, corrupt or over a size limit)."""


def _string(body: memoryview, pos: int) -> tuple[str, int]:
    if pos + 4 > len(body):
        raise McapFormatError("a string runs past its record's end")
    (n,) = struct.unpack_from("<I", body, pos)
    if pos + 4 + n > len(body):
        raise McapFormatError("a string runs past its record's end")
    return str(body[pos + 4 : pos + 4 + n], "utf-8"), pos + 4 + n


def _decompress(compression: str, raw: memoryview, size: int) -> bytes:
    """A chunk's records: ``raw`` decompressed to exactly ``size`` bytes (never more made)."""
    try:
        if compression == "":
            data = bytes(raw)
        elif compression == "zstd":
            import zstandard

            stated = zstandard.frame_content_size(raw)
            if stated > size:
                raise McapFormatError(f"a zstd frame of {stated} bytes in a chunk of {size}")
            data = zstandard.ZstdDecompressor().decompress(raw, max_output_size=size)
        elif compression == "lz4":
            import lz4.frame

            decompressor = lz4.frame.LZ4FrameDecompressor()
            data = decompressor.decompress(raw, max_length=size + 1)
        else:
            raise McapFormatError(f"unsupported compression {compression!r} (lz4, zstd or none)")
    except McapFormatError:
        raise
    except Exception as exc:  # the libraries raise their own error types on corrupt frames
        raise McapFormatError(f"corrupt {compression} chunk ({exc})") from None
    if len(data) != size:
        raise McapFormatError(f"a chunk of {len(data)} bytes of records where it states {size}")
    return data


class _Reader:
    def __init__(self, limit: int, views: bool):
        self.limit = limit
        self.views = views
        self.schemas: dict[int, tuple[str, str, bytes]] = {}
        self.channels: dict[int, tuple[str, str, str, bytes, str]] = {}

    def definition(self, op: int, body: memoryview) -> None:
        if len(body) < 4:
            raise McapFormatError("a schema or channel record too short")
        if op == _SCHEMA:
            (sid,) = struct.unpack_from("<H", body)
            name, pos = _string(body, 2)
            encoding, pos = _string(body, pos)
            if pos + 4 > len(body):
                raise McapFormatError("a schema's data runs past its record's end")
            (n,) = struct.unpack_from("<I", body, pos)
            if pos + 4 + n > len(body):
                raise McapFormatError("a schema's data runs past its record's end")
            self.schemas[sid] = (name, encoding, bytes(body[pos + 4 : pos + 4 + n]))
        else:
            cid, sid = struct.unpack_from("<HH", body)
            topic, pos = _string(body, 4)
            encoding, _ = _string(body, pos)
            self.channels[cid] = (topic, *self.schemas.get(sid, ("", "", b"")), encoding)

    def message(self, body: memoryview) -> RawMessage:
        if len(body) < _MESSAGE.size:
            raise McapFormatError("a message record too short")
        channel_id, _, log_time, _ = _MESSAGE.unpack_from(body)
        channel = self.channels.get(channel_id)
        if channel is None:
            raise McapFormatError(f"message at log time {log_time} ns on channel {channel_id}, never defined")
        data = body[_MESSAGE.size :]
        return RawMessage(*channel, log_time, data if self.views else bytes(data))

    def chunk(self, body: memoryview) -> Iterator[RawMessage]:
        if len(body) < _CHUNK.size + 4:
            raise McapFormatError("a chunk record too short")
        size = _CHUNK.unpack_from(body)[2]
        if size > self.limit:
            raise McapFormatError(f"a chunk of {size} bytes (at most {self.limit})")
        compression, pos = _string(body, _CHUNK.size)
        if pos + 8 > len(body):
            raise McapFormatError("a chunk's records run past its end")
        (n,) = struct.unpack_from("<Q", body, pos)
        if pos + 8 + n > len(body):
            raise McapFormatError("a chunk's records run past its end")
        data = memoryview(_decompress(compression, body[pos + 8 : pos + 8 + n], size))
        at, end = 0, len(data)
        unpack = _RECORD.unpack_from
        while at < end:
            if at + 9 > end:
                raise McapFormatError("a record runs past the end of its chunk")
            op, length = unpack(data, at)
            if at + 9 + length > end:
                raise McapFormatError("a record runs past the end of its chunk")
            record = data[at + 9 : at + 9 + length]
            if op == _MESSAGE_OP:
                yield self.message(record)
            elif op in (_SCHEMA, _CHANNEL):
                self.definition(op, record)
            at += 9 + length


def _read(stream: BinaryIO, n: int) -> bytes:
    data = stream.read(n)
    if len(data) != n:
        raise McapFormatError("the file ends inside a record (truncated)")
    return data


def mcap_messages(stream: BinaryIO, limit: int, views: bool = False) -> Iterator[RawMessage]:
    """The messages of an MCAP stream in file order (see the module docstring), each one's
    ``data`` a memoryview into its chunk when ``views``, else its own bytes; records and chunks
    over ``limit`` bytes are refused."""
    if stream.read(len(MAGIC)) != MAGIC:
        raise McapFormatError("no MCAP magic at its start")
    reader = _Reader(limit, views)
    while True:
        head = _read(stream, _RECORD.size)
        op, length = _RECORD.unpack(head)
        if length > limit:
            raise McapFormatError(f"a record of {length} bytes (at most {limit})")
        body = memoryview(_read(stream, length))
        if op == _CHUNK_OP:
            yield from reader.chunk(body)
        elif op == _MESSAGE_OP:
            yield reader.message(body)
        elif op in (_SCHEMA, _CHANNEL):
            reader.definition(op, body)
        elif op == _FOOTER:
            if stream.read(len(MAGIC)) != MAGIC:
                raise McapFormatError("no MCAP magic after its footer")
            return
