"""Bag files to raw messages: MCAP files (read as a stream, in file order) and ROS 2 bag
directories (``metadata.yaml`` with ``.mcap`` storage files, read in their numbers' order, or
``.db3`` SQLite files, read with ``rosbags``).

Records are bounded before they are read: a record or a chunk's stated uncompressed size over
:data:`MAX_RECORD_BYTES` is refused; a file that ends early is a :class:`UserError` naming the
last message read (topic and log time).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from mcap.exceptions import McapError
from mcap.records import Channel, Chunk, Message, Schema
from mcap.stream_reader import StreamReader, breakup_chunk

from ...errors import UserError, at, first_line
from .messages import RawMessage

MAX_RECORD_BYTES = 1 << 30
"""The largest MCAP record or uncompressed chunk read."""

MCAP_MAGIC = b"\x89MCAP0\r\n"


@dataclass(frozen=True)
class _Topic:
    topic: str
    schema: Schema | None
    encoding: str


def storage_files(path: Path) -> list[Path]:
    """The MCAP files of a bag: the file itself, or a bag directory's ``.mcap`` files in the
    order rosbag2 numbers them (``name_0.mcap``, ``name_1.mcap``, ..., ``name_10.mcap``)."""
    if not path.is_dir():
        return [path]

    def number(file: Path) -> tuple:
        return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", file.name))

    return sorted(path.glob("*.mcap"), key=number)


def _records(stream: BinaryIO) -> Iterator[object]:
    reader = StreamReader(stream, emit_chunks=True, record_size_limit=MAX_RECORD_BYTES)
    for record in reader.records:
        if isinstance(record, Chunk):
            if record.uncompressed_size > MAX_RECORD_BYTES:
                raise McapError(f"a chunk of {record.uncompressed_size} bytes (at most {MAX_RECORD_BYTES})")
            yield from breakup_chunk(record)
        else:
            yield record


def messages(stream: BinaryIO, source: str) -> Iterator[RawMessage]:
    """The messages of an MCAP stream in file order (schemas and channels as they are defined)."""
    schemas: dict[int, Schema] = {}
    channels: dict[int, _Topic] = {}
    last: RawMessage | None = None
    try:
        for record in _records(stream):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = _Topic(record.topic, schemas.get(record.schema_id), record.message_encoding)
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None:
                    raise UserError(
                        f"message at log time {record.log_time} ns on channel {record.channel_id}, never defined",
                        at(source),
                    )
                schema = channel.schema
                last = RawMessage(
                    channel.topic,
                    schema.name if schema else "",
                    schema.encoding if schema else "",
                    schema.data if schema else b"",
                    channel.encoding,
                    record.log_time,
                    record.data,
                )
                yield last
    except (McapError, EOFError, ValueError, KeyError, OSError) as exc:
        after = "at its start" if last is None else f"after topic {last.topic}, message at log time {last.log_time} ns"
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(f"not a valid MCAP file (truncated or corrupt?) {after}: {detail}", at(source)) from None


def bag_messages(path: str | Path) -> Iterator[RawMessage]:
    """Every message of an MCAP file or a ROS 2 bag directory, file after file (a directory of
    ``.db3`` files through :func:`sqlite_messages`)."""
    path = Path(path)
    if path.is_dir() and not any(path.glob("*.mcap")):
        yield from sqlite_messages(path)
        return
    for file in storage_files(path):
        with open(file, "rb") as handle:
            yield from messages(handle, str(file))


def sqlite_messages(path: Path) -> Iterator[RawMessage]:
    """The messages of a ROS 2 bag directory of SQLite (``.db3``) files, read with ``rosbags``
    in log time order. The bag must store its message definitions (rosbag2 bags of format 8 and
    later do); one without is a :class:`UserError`."""
    from rosbags.interfaces import MessageDefinitionFormat
    from rosbags.rosbag2 import Reader
    from rosbags.rosbag2.errors import ReaderError

    last: RawMessage | None = None
    try:
        with Reader(path) as reader:
            for connection, log_time, data in reader.messages():
                definition = connection.msgdef
                if definition.format != MessageDefinitionFormat.MSG or not definition.data:
                    raise UserError(
                        f"topic {connection.topic}: the bag stores no .msg definition of {connection.msgtype}"
                        " (rosbag2 bags before format 8 do not; record it again, or as MCAP)",
                        at(path),
                    )
                encoding = getattr(connection.ext, "serialization_format", "cdr")
                last = RawMessage(
                    connection.topic,
                    connection.msgtype,
                    "ros2msg",
                    definition.data.encode(),
                    encoding,
                    log_time,
                    bytes(data),
                )
                yield last
    except (ReaderError, OSError, ValueError, KeyError) as exc:
        after = "" if last is None else f" after topic {last.topic}, message at log time {last.log_time} ns"
        raise UserError(f"not a valid ROS 2 SQLite bag{after}: {first_line(exc)}", at(path)) from None


def topic_table(path: str | Path) -> list[dict]:
    """Per topic of a bag, in order of first message: its type, message encoding, message count,
    rate (Hz, from the first to the last log time; None under two messages) and whether
    scenegrep decodes it."""
    from .decoders import supported

    table: dict[str, dict] = {}
    for m in bag_messages(path):
        row = table.get(m.topic)
        if row is None:
            row = table[m.topic] = {
                "topic": m.topic,
                "type": m.schema_name,
                "encoding": m.message_encoding,
                "messages": 0,
                "first": m.log_time,
                "last": m.log_time,
                "decoded": supported(m.schema_name, m.message_encoding),
            }
        row["messages"] += 1
        row["first"], row["last"] = min(row["first"], m.log_time), max(row["last"], m.log_time)
    for row in table.values():
        span = row.pop("last") - row.pop("first")
        row["rate_hz"] = (row["messages"] - 1) * 1e9 / span if row["messages"] > 1 and span > 0 else None
    return list(table.values())
