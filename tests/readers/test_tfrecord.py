"""TFRecord framing: records written by a writer defined here are read back; truncation,
corruption and missing files are user errors naming the file and the record."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from scenegrep.errors import UserError
from scenegrep.readers.tfrecord import masked_crc32c, read_records

PAYLOADS = [b"first", b"", bytes(range(256)) * 40]


def write_tfrecord(path: Path, payloads: list[bytes]) -> Path:
    """Write ``payloads`` as a TFRecord file (length, masked CRC of length, data, masked CRC of data)."""
    with open(path, "wb") as handle:
        for data in payloads:
            length = struct.pack("<Q", len(data))
            handle.write(
                length + struct.pack("<I", masked_crc32c(length)) + data + struct.pack("<I", masked_crc32c(data))
            )
    return path


def _error(path: Path) -> UserError:
    with pytest.raises(UserError) as caught:
        list(read_records(path))
    return caught.value


def test_crc32c_known_value() -> None:
    # CRC-32C("123456789") = 0xE3069283 (the standard check value); masked as TFRecord does.
    crc = 0xE3069283
    assert masked_crc32c(b"123456789") == ((((crc >> 15) | (crc << 17)) & 0xFFFFFFFF) + 0xA282EAD8) & 0xFFFFFFFF


def test_round_trip(tmp_path: Path) -> None:
    path = write_tfrecord(tmp_path / "a.tfrecord", PAYLOADS)
    assert list(read_records(path)) == PAYLOADS


def test_empty_file_holds_no_records(tmp_path: Path) -> None:
    path = tmp_path / "empty.tfrecord"
    path.write_bytes(b"")
    assert list(read_records(path)) == []


@pytest.mark.parametrize(("cut", "at_byte"), [(3, 0), (12 + 2, 12), (12 + 5 + 2, 12)])
def test_truncated_second_record(tmp_path: Path, cut: int, at_byte: int) -> None:
    """Files cut ``cut`` bytes into the second record (in its header, data, footer); the
    error names the part that starts ``at_byte`` bytes into the record."""
    whole = write_tfrecord(tmp_path / "whole.tfrecord", [b"first", b"12345"]).read_bytes()
    first_size = 12 + 5 + 4
    path = tmp_path / "cut.tfrecord"
    path.write_bytes(whole[: first_size + cut])
    error = _error(path)
    assert str(path) in error.one_line()
    assert "record 2" in error.one_line() and "truncated" in error.one_line()
    assert f"at byte {first_size + at_byte}:" in error.one_line()


@pytest.mark.parametrize(("offset", "what"), [(2, "record length"), (12 + 1, "record data"), (12 + 5, "record data")])
def test_flipped_byte_is_a_crc_mismatch(tmp_path: Path, offset: int, what: str) -> None:
    """A flipped bit in the length, the data or the data CRC of the first record."""
    data = bytearray(write_tfrecord(tmp_path / "a.tfrecord", PAYLOADS).read_bytes())
    data[offset] ^= 0x10
    path = tmp_path / "flipped.tfrecord"
    path.write_bytes(bytes(data))
    error = _error(path)
    assert str(path) in error.one_line()
    assert f"CRC mismatch in the {what}" in error.one_line() and "record 1" in error.one_line()


def test_missing_file(tmp_path: Path) -> None:
    error = _error(tmp_path / "absent.tfrecord")
    assert "no such file" in error.one_line() and "absent.tfrecord" in error.one_line()


def test_real_file_frames_one_record(real_data: Path) -> None:
    """A file written by TensorFlow: one record filling the whole file, both CRCs valid."""
    path = real_data / "waymo_womd" / "motion_data_one_scenario.tfrecord"
    records = list(read_records(path))
    assert len(records) == 1
    assert len(records[0]) == path.stat().st_size - 16
