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
from pathlib import Path
from typing import BinaryIO

from ...errors import UserError, at, first_line
from .chunks import mcap_runs
from .messages import RawMessage

MAX_RECORD_BYTES = 1 << 30
"""The largest MCAP record or uncompressed chunk read."""


def storage_files(path: Path) -> list[Path]:
    """The MCAP files of a bag: the file itself, or a bag directory's ``.mcap`` files in the
    order rosbag2 numbers them (``name_0.mcap``, ``name_1.mcap``, ..., ``name_10.mcap``)."""
    if not path.is_dir():
        return [path]

    def number(file: Path) -> tuple:
        return tuple(int(p) if p.isdigit() else p for p in re.split(r"(\d+)", file.name))

    return sorted(path.glob("*.mcap"), key=number)


def runs(stream: BinaryIO, source: str, views: bool = False) -> Iterator[list[RawMessage]]:
    """The messages of an MCAP stream in file order (schemas and channels as they are defined), in
    runs (a chunk's: :func:`.chunks.mcap_runs`); with ``views`` each message's ``data`` is a
    memoryview into its decompressed chunk, else bytes."""
    last: RawMessage | None = None
    try:
        for run in mcap_runs(stream, MAX_RECORD_BYTES, views):
            last = run[-1]
            yield run
    except (ValueError, OSError) as exc:  # McapFormatError, a string not UTF-8
        after = "at its start" if last is None else f"after topic {last.topic}, message at log time {last.log_time} ns"
        detail = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise UserError(f"not a valid MCAP file (truncated or corrupt?) {after}: {detail}", at(source)) from None


def messages(stream: BinaryIO, source: str, views: bool = False) -> Iterator[RawMessage]:
    """The messages of :func:`runs`, one at a time."""
    for run in runs(stream, source, views):
        yield from run


def bag_runs(path: str | Path, views: bool = False) -> Iterator[list[RawMessage]]:
    """Every message of an MCAP file or a ROS 2 bag directory, file after file (a directory of
    ``.db3`` files through :func:`sqlite_messages`, a message a run), in runs (:func:`runs`);
    ``views``: an MCAP message's ``data`` is a memoryview into its chunk (the offline reader
    decodes each chunk's messages as it comes, without a copy)."""
    path = Path(path)
    if path.is_dir() and not any(path.glob("*.mcap")):
        yield from ([m] for m in sqlite_messages(path))
        return
    for file in storage_files(path):
        with open(file, "rb") as handle:
            yield from runs(handle, str(file), views)


def bag_messages(path: str | Path, views: bool = False) -> Iterator[RawMessage]:
    """The messages of :func:`bag_runs`, one at a time."""
    for run in bag_runs(path, views):
        yield from run


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
