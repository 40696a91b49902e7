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

Parsing is done by a small C extension (:mod:`scenegrep.readers._strem`, built from
``_strem.c`` by ``setup.py`` at install) straight into columns; files are memory-mapped and
their pages released as they are parsed, so a stream of any size is read at a few hundred
MB/s in little memory.

Why C and not ``msgspec`` (as the other JSON readers): ``benchmarks/bench_strem_parse.py``
decodes the same bytes into the same columns both ways in one run (typed msgspec Structs,
then ``attrgetter`` maps into ``numpy.fromiter``; the columns are checked equal) and times
``scenegrep spre --compat strem`` end to end with each. On 2026-11-24 (2 cores shared with other jobs, medians
of 5): 20k generated frames (12.6 MB) 24.5 ms in C against 224 ms with msgspec (9.1x);
100k frames (62.8 MB) 149 ms against 1183 ms (8.0x); 20k frames of two channels with
oriented boxes 49 ms against 375 ms (7.6x); the conformance streams 5-14x (microseconds).
End to end over 100k frames: ``[[:car:] & [:pedestrian:]]{2,5}`` 0.77 s with C (0.47 x
STREM v0.2.0's 1.65 s) against 1.93 s with msgspec (1.17 x STREM's), ``[[:car:]]`` 1.10 s
(0.66 x) against 2.26 s (1.37 x); peak memory 154 MB against 388 MB (STREM: 254 MB). The C
parser is what keeps SpRE ahead of STREM in time and memory, so it stays; rerun the benchmark
when either side changes.
"""

from __future__ import annotations

import mmap
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np

from ..errors import UserError, at
from ..model import BoxTable, ImageLayer, LabelTrace, ObjectTable, SampleTable, StateTable, TraceSource
from ..writers.strem_json import STREM_VERSION
from . import _strem
from .common import STDIN, display_name, malformed, reading
from .json_locate import line_column
from .json_stream import DocumentSplitter

FORMAT = "strem-json"


def _trace(columns: dict, name: str, source: TraceSource) -> LabelTrace:
    """A trace from the columns the C parser returns."""
    c = {k: v for k, v in columns.items() if isinstance(v, bytes)}
    int32 = {k: np.frombuffer(c[k], np.int32) for k in c if k.startswith(("sample_", "box_sample", "box_class"))}
    f64 = {
        k: np.frombuffer(c[k], np.float64)
        for k in ("frame_time", "box_score", "box_cx", "box_cy", "box_w", "box_h", "box_rotation")
    }
    paths = np.array(columns["paths"] or [""], dtype=object)[int32["sample_path"]]
    samples = SampleTable(
        tuple(columns["channels"]),
        int32["sample_frame"],
        int32["sample_channel"],
        paths,
        int32["sample_width"],
        int32["sample_height"],
    )
    boxes = BoxTable(
        tuple(columns["classes"]),
        int32["box_sample"],
        int32["box_class"],
        f64["box_score"].astype(np.float32),
        f64["box_cx"],
        f64["box_cy"],
        f64["box_w"],
        f64["box_h"],
        f64["box_rotation"],
        np.frombuffer(c["box_oriented"], np.uint8).astype(bool),
        np.full(len(f64["box_cx"]), -1, dtype=np.int32),
    )
    return LabelTrace.build(
        name,
        np.frombuffer(c["frame_index"], np.int64),
        f64["frame_time"],
        ObjectTable.build([], []),
        StateTable.build([], [], [], [], []),
        images=ImageLayer(samples, boxes),
        source=source,
    )


def decode(data: bytes | mmap.mmap, source: str, name: str, release: bool = False) -> LabelTrace:
    """The stream of all documents in ``data`` as one trace (STREM's semantics for a file).

    ``release``: ``data`` is a read-only file mapping whose pages may be dropped once parsed.
    """
    try:
        columns = _strem.parse(data, release=release)
    except ValueError as exc:
        message, offset, where = exc.args
        raise UserError(message, at(source, *line_column(data[:offset], offset), path=where or None)) from None
    for version, offset in columns["versions"]:
        if version != STREM_VERSION:
            raise UserError(
                f"unsupported STREM version {version!r}: expected {STREM_VERSION}",
                at(source, *line_column(data[:offset], offset), path="version"),
            )
    with malformed(source, FORMAT):
        return _trace(columns, name, TraceSource(source, FORMAT))


def read_trace(path: str | Path) -> LabelTrace:
    """Read a STREM JSON file (``-`` reads all of standard input)."""
    if str(path) == STDIN:
        return decode(sys.stdin.buffer.read(), display_name(path), "stdin")
    with reading(path, "STREM JSON file"), open(path, "rb") as handle:
        if Path(path).stat().st_size == 0:
            return decode(b"", display_name(path), Path(path).stem)
        with mmap.mmap(handle.fileno(), 0, access=mmap.ACCESS_READ) as mapped:
            return decode(mapped, display_name(path), Path(path).stem, release=True)


def iter_documents(stream: BinaryIO, source: str = "<stdin>", chunk_size: int = 1 << 16) -> Iterator[LabelTrace]:
    """The documents of a stream as traces, as soon as they have arrived (the online feed):
    the documents completed by each read form one trace.

    Reads with ``read1`` where available so a document is handed on without waiting
    for a full chunk. Frame positions restart at 0 in every trace.
    """
    splitter = DocumentSplitter()
    read = getattr(stream, "read1", stream.read)
    while chunk := read(chunk_size):
        documents = splitter.feed(chunk)
        if documents:
            yield decode(b"\n".join(documents), source, "stdin")
    if splitter.remainder():
        raise UserError("unexpected end of input (truncated JSON document)", at(source))
