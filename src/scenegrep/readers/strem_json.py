"""STREM JSON v0.2.0 perception streams (2-D detections per camera channel).

The format is described in docs/strem-reference.md §1: ``{"version": "0.2.0",
"frames": [{"index", "samples": [{"type": "@stremf/sample/detection", "channel",
"image": {"path", "dimensions": {"width", "height"}}, "annotations": [{"class",
"score", "bbox": {"type": "@stremf/bbox/aabb" | "@stremf/bbox/obb", "region":
{"center": {"x", "y"}, "dimensions": {"w", "h"}, "rotation"}}}]}]}]}``.
A file (or standard input) may hold several such documents back to back; their
frames form one stream. Unknown fields are ignored, as STREM does; an optional
per-frame ``timestamp`` (seconds) is read when present (STREM ignores it), and
frame times are NaN otherwise. A version other than 0.2.0 is rejected.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import Annotated, BinaryIO
from collections.abc import Iterator

import msgspec
import numpy as np
from msgspec import Meta, Raw, Struct

from ..errors import UserError, at
from ..model import LabelTrace, ObjectTable, StateTable, TraceSource
from ..model.images import ImageLayerBuilder
from .common import STDIN, display_name, read_bytes
from .json_locate import byte_offset, line_column, msgspec_error, parse_path, path_text
from .json_stream import DocumentSplitter

FORMAT = "strem-json"
STREM_VERSION = "0.2.0"
BATCH_FRAMES = 4096
"""Frames decoded per batch: bounds the memory of decoded objects."""

Unsigned = Annotated[int, Meta(ge=0)]
Pixels = Annotated[int, Meta(ge=0, le=2**32 - 1)]


class _Point(Struct, gc=False):
    x: float
    y: float


class _Size(Struct, gc=False):
    w: float
    h: float


class _AxisRegion(Struct, gc=False):
    center: _Point
    dimensions: _Size


class _OrientedRegion(Struct, gc=False):
    center: _Point
    dimensions: _Size
    rotation: float


class _Aabb(Struct, gc=False, tag_field="type", tag="@stremf/bbox/aabb"):
    region: _AxisRegion


class _Obb(Struct, gc=False, tag_field="type", tag="@stremf/bbox/obb"):
    region: _OrientedRegion


class _Annotation(Struct, gc=False, rename={"category": "class"}):
    category: str
    score: float
    bbox: _Aabb | _Obb


class _ImageSize(Struct, gc=False):
    width: Pixels
    height: Pixels


class _Image(Struct, gc=False):
    path: str
    dimensions: _ImageSize


class _Sample(Struct, gc=False, tag_field="type", tag="@stremf/sample/detection"):
    channel: str
    image: _Image
    annotations: list[_Annotation]


class _Frame(Struct, gc=False):
    index: Unsigned
    samples: list[_Sample]
    timestamp: float | None = None


class _Document(Struct):
    version: str
    frames: list[Raw]


_DOCUMENT = msgspec.json.Decoder(_Document)
_FRAMES = msgspec.json.Decoder(list[_Frame])
_TRAILING = re.compile(r"trailing characters \(byte (\d+)\)")


class _Columns:
    """The frames and image layer of a stream being read."""

    def __init__(self) -> None:
        self.frame_index: list[int] = []
        self.frame_time: list[float] = []
        self.images = ImageLayerBuilder()

    def add(self, frames: list[_Frame]) -> None:
        add_sample, add_box = self.images.add_sample, self.images.add_box
        for frame in frames:
            position = len(self.frame_index)
            self.frame_index.append(frame.index)
            self.frame_time.append(np.nan if frame.timestamp is None else frame.timestamp)
            for sample in frame.samples:
                image = sample.image
                row = add_sample(position, sample.channel, image.path, image.dimensions.width, image.dimensions.height)
                for ann in sample.annotations:
                    region = ann.bbox.region
                    rotation = region.rotation if type(region) is _OrientedRegion else None
                    add_box(
                        row,
                        ann.category,
                        ann.score,
                        region.center.x,
                        region.center.y,
                        region.dimensions.w,
                        region.dimensions.h,
                        rotation,
                    )

    def trace(self, name: str, source: TraceSource) -> LabelTrace:
        return LabelTrace.build(
            name,
            self.frame_index,
            self.frame_time,
            ObjectTable.build([], []),
            StateTable.build([], [], [], [], []),
            images=self.images.build(),
            source=source,
        )


def _split_documents(data: bytes, source: str) -> Iterator[tuple[int, _Document]]:
    """(byte offset, decoded document) for each top-level document of ``data``."""
    start = len(data) - len(data.lstrip())
    while start < len(data):
        try:
            yield start, _DOCUMENT.decode(data[start:])
            return
        except msgspec.DecodeError as exc:
            found = _TRAILING.search(str(exc))
            if not found:
                raise msgspec_error(exc, data, start, source) from None
        end = start + int(found.group(1)) - 1  # msgspec reports the byte after the offending one
        try:
            yield start, _DOCUMENT.decode(data[start:end])
        except msgspec.MsgspecError as exc:
            raise msgspec_error(exc, data, start, source) from None
        start = end + len(data[end:]) - len(data[end:].lstrip())


def _frame_offsets(data: bytes, doc_start: int, frames: list[Raw], upto: int) -> int:
    """Byte offset in ``data`` of frame ``upto`` of the document at ``doc_start``."""
    pos = data.find(b"[", data.find(b'"frames"', doc_start))
    for raw in frames[: upto + 1]:
        pos = data.find(bytes(raw), pos)
    return pos


def _add_document(columns: _Columns, data: bytes, start: int, doc: _Document, source: str) -> None:
    if doc.version != STREM_VERSION:
        offset = start + byte_offset(data[start:], ["version"])
        raise UserError(
            f"unsupported STREM version {doc.version!r}: expected {STREM_VERSION}",
            at(source, *line_column(data, offset)),
        )
    for first in range(0, len(doc.frames), BATCH_FRAMES):
        batch = doc.frames[first : first + BATCH_FRAMES]
        try:
            frames = _FRAMES.decode(b"[" + b",".join(bytes(r) for r in batch) + b"]")
        except msgspec.ValidationError as exc:
            message, _, path = str(exc).partition(" - at `")
            parts = parse_path(path.rstrip("`"))
            k = first + int(parts[0])
            frame_start = _frame_offsets(data, start, doc.frames, k)
            offset = frame_start + byte_offset(data[frame_start:], parts[1:])
            where = path_text(["frames", k, *parts[1:]])
            raise UserError(message, at(source, *line_column(data, offset), path=where)) from None
        columns.add(frames)


def decode(data: bytes, source: str, name: str) -> LabelTrace:
    """The stream of all documents in ``data`` as one trace (STREM's semantics for a file)."""
    columns = _Columns()
    for start, doc in _split_documents(data, source):
        _add_document(columns, data, start, doc, source)
    return columns.trace(name, TraceSource(source, FORMAT))


def read_trace(path: str | Path) -> LabelTrace:
    """Read a STREM JSON file (``-`` reads all of standard input)."""
    if str(path) == STDIN:
        return decode(sys.stdin.buffer.read(), display_name(path), "stdin")
    return decode(read_bytes(path), display_name(path), Path(path).stem)


def iter_documents(stream: BinaryIO, source: str = "<stdin>", chunk_size: int = 1 << 16) -> Iterator[LabelTrace]:
    """Each document of a stream as a trace, as soon as it has arrived (the online feed).

    Reads with ``read1`` where available so a document is handed on without waiting
    for a full chunk. Frame positions restart at 0 in every document.
    """
    splitter = DocumentSplitter()
    read = getattr(stream, "read1", stream.read)
    while chunk := read(chunk_size):
        for document in splitter.feed(chunk):
            yield decode(document, source, "stdin")
    rest = splitter.remainder()
    if rest:
        raise UserError("unexpected end of input (truncated JSON document)", at(source))
