"""The messages of an MCAP file read offline, in file order, each a view into its decompressed
chunk (no copy).

The top-level records are read from the file one at a time: a record's length is checked
against ``limit`` before its body is read, so a corrupt length cannot exhaust memory; each body
is parsed by :class:`~scenegrep.readers.mcap_records.Records` (the one MCAP record parser, shared
with the live follower: its bounds, decompression and error texts). The file ends at its Footer
and the magic after it. A fault is an :class:`McapFormatError` naming the record and its byte
offset; the caller names the file and the last message read.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import BinaryIO

from ..mcap_records import FOOTER, HEADER, MAGIC, McapFormatError, RawMessage, Records, check_size, describe

__all__ = ["McapFormatError", "mcap_messages", "mcap_runs"]


def _read(stream: BinaryIO, n: int, offset: int, opcode: int | None) -> bytes:
    """``n`` bytes of the record at ``offset`` (its header when ``opcode`` is None, else its body)."""
    data = stream.read(n)
    if len(data) != n:
        reason = "the file ends inside a record's header" if opcode is None else "truncated"
        raise McapFormatError(describe(offset, opcode, f"{reason}: {n} bytes announced, {len(data)} in the file"))
    return data


def mcap_runs(stream: BinaryIO, limit: int, views: bool = False) -> Iterator[list[RawMessage]]:
    """The messages of an MCAP stream in file order (see the module docstring) in runs (a chunk's,
    :meth:`Records.runs`), each one's ``data`` a memoryview into its chunk when ``views``, else
    its own bytes; records and chunks over ``limit`` bytes are refused."""
    if stream.read(len(MAGIC)) != MAGIC:
        raise McapFormatError("no MCAP magic at its start")
    records = Records(limit, views)
    offset = len(MAGIC)
    while True:
        opcode, length = HEADER.unpack(_read(stream, HEADER.size, offset, None))
        check_size(offset, opcode, length, limit)
        body = memoryview(_read(stream, length, offset, opcode))
        if opcode == FOOTER:
            if stream.read(len(MAGIC)) != MAGIC:
                raise McapFormatError("no MCAP magic after its footer")
            return
        yield from records.runs(offset, opcode, body)
        offset += HEADER.size + length


def mcap_messages(stream: BinaryIO, limit: int, views: bool = False) -> Iterator[RawMessage]:
    """The messages of :func:`mcap_runs`, one at a time."""
    for run in mcap_runs(stream, limit, views):
        yield from run
