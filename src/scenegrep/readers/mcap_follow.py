"""Raw messages of an MCAP stream while it is being written: a growing file (``--follow``) or standard input.

:func:`follow_mcap` yields :class:`RawMessage` tuples (topic, schema name, encoding and data, message
encoding, log time in ns, payload) in the stream's record order, each as soon as the record that carries
it has wholly arrived: a Message record, or for messages inside a Chunk record the whole chunk (a
live writer that wants each message seen at once writes unchunked, e.g. ``noChunking: true`` in the
storage configuration of ``ros2 bag record -s mcap``, or small chunks).

* Records are framed by their own prefix (opcode: 1 byte, length: 8 bytes, little-endian) and parsed
  only once all their bytes are there, so a half-written record is never read; a file is read from
  the start and polled every ``poll`` seconds for appended bytes. Their bodies are parsed by
  :class:`~scenegrep.readers.mcap_records.Records`, the MCAP record parser the offline bag reader
  uses too.
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
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

from ..errors import UserError, at
from .mcap_records import DATA_END, FOOTER, HEADER, MAGIC, McapFormatError, RawMessage, Records, check_size, describe

__all__ = ["MAGIC", "FollowOptions", "MessageStream", "RawMessage", "follow_mcap", "sniff_mcap"]
POLL_SECONDS = 0.01
"""Default poll interval of a followed file: 10 ms, a tenth of the 100 ms latency budget, at the cost
of ~100 empty reads a second while the writer is idle."""
MAX_RECORD_BYTES = 256 * 2**20
READ_BLOCK = 2**20
BATCH_MESSAGES = 4096
"""The most messages :meth:`MessageStream.batches` hands out together."""


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
        self._parser = Records(options.max_record)

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
            elif opcode in (DATA_END, FOOTER):
                return
            else:
                try:
                    for message in self._parser.messages(offset, opcode, body):
                        self.arrival = time.perf_counter()
                        yield message
                except McapFormatError as exc:
                    raise UserError(str(exc), at(self.name)) from None

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
            whole = len(buffer) >= HEADER.size and len(buffer) >= HEADER.size + HEADER.unpack_from(buffer)[1]
            if source.caught_up and not whole:
                yield offset, 0, None
            if not fill(HEADER.size):
                if buffer:
                    raise self._error(offset, None, "the stream ends inside a record's header")
                return
            opcode, length = HEADER.unpack_from(buffer)
            self._check_size(offset, opcode, length)
            if not fill(HEADER.size + length):
                raise self._error(offset, opcode, f"truncated: {length} bytes announced, {len(buffer) - 9} arrived")
            end = HEADER.size + length
            yield offset, opcode, memoryview(bytes(buffer[HEADER.size : end]))
            del buffer[:end]
            offset += end

    def _check_size(self, offset: int, opcode: int, size: int) -> None:
        try:
            check_size(offset, opcode, size, self.options.max_record)
        except McapFormatError as exc:
            raise UserError(str(exc), at(self.name)) from None

    def _error(self, offset: int, opcode: int | None, message: str) -> UserError:
        return UserError(describe(offset, opcode, message), at(self.name))


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
