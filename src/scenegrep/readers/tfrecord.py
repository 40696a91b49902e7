"""TFRecord files: the record framing TensorFlow writes, read without TensorFlow.

A TFRecord file is a sequence of records, each::

    uint64  length                   little-endian, bytes of data
    uint32  masked_crc32c(length)    over the 8 length bytes, little-endian
    byte    data[length]
    uint32  masked_crc32c(data)      little-endian

where ``masked_crc32c(x) = ((c >> 15) | (c << 17)) + 0xa282ead8`` (mod 2**32) and
``c`` is the CRC-32C (Castagnoli) of ``x``, computed by the C extension of
``google-crc32c``. Files are read as a stream, one record at a time, so shards of
any size can be scanned. Records are numbered from 1 in messages; byte offsets
count from the start of the file.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path
from typing import BinaryIO
from collections.abc import Iterator

import google_crc32c

from ..errors import SourceLocation, UserError, at
from .common import reading

_HEADER = struct.Struct("<QI")
"""The record header: data length, masked CRC of the length bytes."""

_FOOTER = struct.Struct("<I")
"""The record footer: masked CRC of the data."""

_MASK_DELTA = 0xA282EAD8


def masked_crc32c(data: bytes) -> int:
    """The masked CRC-32C of ``data`` as TFRecord stores it (an unsigned 32-bit integer)."""
    crc = google_crc32c.value(data)
    return ((((crc >> 15) | (crc << 17)) & 0xFFFFFFFF) + _MASK_DELTA) & 0xFFFFFFFF


def record_location(path: str | Path, number: int) -> SourceLocation:
    """Where record ``number`` (from 1) of a file is, for error messages."""
    return at(path, path=f"record {number}")


def _truncated(path: str | Path, number: int, offset: int, what: str, size: int, got: int) -> UserError:
    """The error for a ``what`` of ``size`` bytes at byte ``offset`` of which the file holds only ``got``."""
    return UserError(
        f"truncated {what} at byte {offset}: expected {size} bytes, the file ends after {got}",
        record_location(path, number),
    )


def _check_crc(data: bytes, expected: int, path: str | Path, number: int, offset: int, what: str) -> None:
    """UserError unless ``data`` (starting at byte ``offset``) has the masked CRC ``expected``."""
    if masked_crc32c(data) != expected:
        raise UserError(f"CRC mismatch in the {what} at byte {offset} (corrupt file?)", record_location(path, number))


def _records(handle: BinaryIO, path: str | Path) -> Iterator[bytes]:
    """The checked record data read from an open TFRecord file (see :func:`read_records`)."""
    offset = 0
    number = 1
    while head := handle.read(_HEADER.size):
        if len(head) != _HEADER.size:
            raise _truncated(path, number, offset, "record header", _HEADER.size, len(head))
        length, length_crc = _HEADER.unpack(head)
        _check_crc(head[:8], length_crc, path, number, offset, "record length")
        data_offset = offset + _HEADER.size
        available = os.fstat(handle.fileno()).st_size - data_offset
        if length + _FOOTER.size > available:
            raise _truncated(path, number, data_offset, "record data", length + _FOOTER.size, available)
        body = handle.read(length + _FOOTER.size)
        if len(body) != length + _FOOTER.size:
            raise _truncated(path, number, data_offset, "record data", length + _FOOTER.size, len(body))
        data = body[:length]
        _check_crc(data, _FOOTER.unpack_from(body, length)[0], path, number, data_offset, "record data")
        yield data
        offset = data_offset + length + _FOOTER.size
        number += 1


def read_records(path: str | Path) -> Iterator[bytes]:
    """The data of every record of a TFRecord file, in file order, read lazily.

    Both CRCs of every record are checked. A missing or unreadable file, a truncated
    record or a CRC mismatch is a :class:`UserError` naming the file, the record number
    and the byte offset.
    """
    with reading(path, "TFRecord file"), open(path, "rb") as handle:
        yield from _records(handle, path)
