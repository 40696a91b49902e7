"""STREM JSON parsing: the C extension (``scenegrep.readers._strem``) against ``msgspec``, in one run.

Decodes the same bytes into the same columns both ways and checks the columns are equal
(every bytes column and every string table), then times each ``--repeat`` times after a
warm-up (median, min..max, MB/s, ratio). Inputs: the real STREM streams that exist (the
conformance streams of ../shared/conformance/strem/data that STREM accepts;
../shared/real_data holds no STREM streams: its recordings carry 3-D tracks, not image
detections) and generated streams of 20k and 100k frames as STREM's own benchmark (one
channel, 0-6 boxes per frame, bench_spre.write_stream) plus a two-channel stream with
oriented boxes and timestamps. Then, end to end, ``scenegrep spre --compat strem QUERY FILE``
(process start, import, parse, match, print) with each parser over the 100k stream, against
STREM v0.2.0's published time (bench_spre.STREM_SECONDS).

The msgspec decoder is typed (``msgspec.Struct`` per JSON object, as the other JSON readers
do) and turns the objects into columns with ``operator.attrgetter`` maps into
``numpy.fromiter``, the fastest pure-Python way found; ``--spre-with msgspec`` runs the
command line with it in place of the C parser.

    python benchmarks/bench_strem_parse.py [--repeat 5] [--quick] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import sys
import tempfile
from functools import partial
from operator import attrgetter
from pathlib import Path
from typing import Literal

import msgspec
import numpy as np
from msgspec import UNSET, Struct, UnsetType

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
sys.path.insert(0, str(REPO / "benchmarks"))

from bench_spre import STREM_SECONDS, frame, measure, write_stream  # noqa: E402
from timing import repeated_seconds  # noqa: E402
from scenegrep.readers import _strem  # noqa: E402
from scenegrep.readers.json_stream import DocumentSplitter  # noqa: E402

CONFORMANCE = REPO.parent / "shared" / "conformance" / "strem" / "data"
SPRE_QUERIES = [("atom", "[[:car:]]"), ("and range", "[[:car:] & [:pedestrian:]]{2,5}")]


class Point(Struct, gc=False):
    x: float
    y: float


class Size(Struct, gc=False):
    w: float
    h: float


class Region(Struct, gc=False):
    center: Point
    dimensions: Size
    rotation: float | UnsetType = UNSET


class Bbox(Struct, gc=False):
    type: Literal["@stremf/bbox/aabb", "@stremf/bbox/obb"]
    region: Region


class Annotation(Struct, gc=False):
    category: str = msgspec.field(name="class")
    score: float
    bbox: Bbox


class ImageSize(Struct, gc=False):
    width: int
    height: int


class Image(Struct, gc=False):
    path: str
    dimensions: ImageSize


class Sample(Struct, gc=False):
    type: Literal["@stremf/sample/detection"]
    channel: str
    image: Image
    annotations: list[Annotation]


class Frame(Struct, gc=False):
    index: int
    samples: list[Sample]
    timestamp: float | None = None


class Document(Struct, gc=False):
    version: str
    frames: list[Frame]


_DECODER = msgspec.json.Decoder(Document)


def _documents(data: bytes) -> list[Document]:
    """Every document of ``data`` (a bytes-like object or a file mapping): one decode when it
    holds one document, the common case."""
    try:
        return [_DECODER.decode(data)]
    except msgspec.DecodeError as exc:
        if "trailing characters" not in str(exc) and bytes(data).strip():
            raise
    return [_DECODER.decode(document) for document in DocumentSplitter().feed(bytes(data))]


def _column(items: list, getter: attrgetter, dtype: type | str) -> np.ndarray:
    return np.fromiter(map(getter, items), dtype, len(items))


def _codes(values: list[str]) -> tuple[list[str], np.ndarray]:
    """Codes by first appearance (as the C parser interns) and the table of strings."""
    table: dict[str, int] = {}
    codes = np.fromiter(map(lambda v: table.setdefault(v, len(table)), values), np.int32, len(values))
    return list(table), codes


def msgspec_parse(data: bytes, release: bool = False) -> dict:
    """The columns :func:`scenegrep.readers._strem.parse` returns, decoded with msgspec.
    ``release`` is accepted for the same signature and ignored."""
    documents = _documents(data)
    frames = [f for d in documents for f in d.frames]
    samples = [s for f in frames for s in f.samples]
    boxes = [a for s in samples for a in s.annotations]
    per_frame = _column(frames, attrgetter("samples"), object)
    per_sample = _column(samples, attrgetter("annotations"), object)
    channels, channel = _codes(list(map(attrgetter("channel"), samples)))
    paths, path = _codes(list(map(attrgetter("image.path"), samples)))
    classes, category = _codes(list(map(attrgetter("category"), boxes)))
    oriented = np.fromiter((b.bbox.type == "@stremf/bbox/obb" for b in boxes), np.uint8, len(boxes))
    rotation = np.fromiter(
        (r if r is not UNSET else 0.0 for r in map(attrgetter("bbox.region.rotation"), boxes)), float
    )
    times = np.fromiter((t if t is not None else np.nan for t in map(attrgetter("timestamp"), frames)), float)
    sizes = {k: _column(samples, attrgetter(f"image.dimensions.{k}"), np.int64) for k in ("width", "height")}
    columns = {
        "frame_index": _column(frames, attrgetter("index"), np.int64),
        "frame_time": times,
        "sample_frame": np.repeat(np.arange(len(frames), dtype=np.int32), np.fromiter(map(len, per_frame), np.int64)),
        "sample_channel": channel,
        "sample_path": path,
        "sample_width": sizes["width"].astype(np.uint32).view(np.int32),
        "sample_height": sizes["height"].astype(np.uint32).view(np.int32),
        "box_sample": np.repeat(np.arange(len(samples), dtype=np.int32), np.fromiter(map(len, per_sample), np.int64)),
        "box_class": category,
        "box_score": _column(boxes, attrgetter("score"), float),
        "box_cx": _column(boxes, attrgetter("bbox.region.center.x"), float),
        "box_cy": _column(boxes, attrgetter("bbox.region.center.y"), float),
        "box_w": _column(boxes, attrgetter("bbox.region.dimensions.w"), float),
        "box_h": _column(boxes, attrgetter("bbox.region.dimensions.h"), float),
        "box_rotation": np.where(oriented.astype(bool), rotation, 0.0),
        "box_oriented": oriented,
    }
    return {
        **{k: v.tobytes() for k, v in columns.items()},
        "channels": channels,
        "classes": classes,
        "paths": paths,
        "versions": [(d.version, 0) for d in documents],
    }


def same_columns(c: dict, m: dict) -> bool:
    """Whether both parsers gave the same columns (byte offsets of versions aside)."""
    return all(c[k] == m[k] for k in c if k != "versions") and [v for v, _ in c["versions"]] == [
        v for v, _ in m["versions"]
    ]


def two_channel_stream(path: Path, n: int) -> Path:
    """``n`` frames with timestamps, a front and a back camera, axis-aligned and oriented boxes."""
    rng = random.Random(n)
    with open(path, "w") as out:
        out.write('{"version":"0.2.0","frames":[')
        for i in range(n):
            record = frame(i, rng, ("car", "pedestrian", "bus", "truck"), (0, 6))
            back = json.loads(json.dumps(record["samples"][0]))
            back["channel"] = "cam::back"
            for box in back["annotations"]:
                box["bbox"]["type"] = "@stremf/bbox/obb"
                box["bbox"]["region"]["rotation"] = round(rng.uniform(-3.14, 3.14), 3)
            record["samples"].append(back)
            record["timestamp"] = round(i * 0.1, 1)
            out.write(("," if i else "") + json.dumps(record, separators=(",", ":")))
        out.write("]}")
    return path


def parse_rows(inputs: list[tuple[str, bytes]], repeat: int) -> list[dict]:
    rows = []
    for label, data in inputs:
        reference = _strem.parse(data)
        if not same_columns(reference, msgspec_parse(data)):
            raise SystemExit(f"{label}: the two parsers disagree")
        row = {"input": label, "mb": len(data) / 1e6, "frames": len(reference["frame_index"]) // 8}
        for name, parse in (("c", _strem.parse), ("msgspec", msgspec_parse)):
            times = repeated_seconds(partial(parse, data), repeat)
            row |= {
                f"{name}_median_s": statistics.median(times),
                f"{name}_min_s": min(times),
                f"{name}_max_s": max(times),
            }
        row["ratio"] = row["msgspec_median_s"] / row["c_median_s"]
        rows.append(row)
    return rows


def spre_rows(path: Path, frames: int, repeat: int) -> list[dict]:
    rows = []
    for label, query in SPRE_QUERIES:
        for parser in ("c", "msgspec"):
            command = [sys.executable, __file__, "--spre-with", parser, "spre", "--compat", "strem", query, str(path)]
            rows.append({**measure(f"{label}: {query}", frames, command, repeat), "parser": parser})
    return rows


def run_spre(parser: str, arguments: list[str]) -> int:
    """The command line, with the C parser or the msgspec decoder in its place."""
    from scenegrep.cli.main import main
    from scenegrep.readers import strem_json

    if parser == "msgspec":
        strem_json._strem = sys.modules[__name__]
    return main(arguments)


parse = msgspec_parse
"""So that this module stands in for ``_strem`` under ``--spre-with msgspec``."""


def main() -> None:
    if len(sys.argv) > 2 and sys.argv[1] == "--spre-with":
        raise SystemExit(run_spre(sys.argv[2], sys.argv[3:]))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="smaller streams, for a smoke run")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON here")
    args = parser.parse_args()
    small, large = (2_000, 10_000) if args.quick else (20_000, 100_000)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        real = [
            p for p in sorted(CONFORMANCE.glob("*.json")) if p.stem not in ("fmt_bad_bbox_type", "fmt_missing_image")
        ]
        inputs = [(f"conformance/{p.name}", p.read_bytes()) for p in real]
        generated = {n: write_stream(folder / f"typical_{n}.json", n) for n in (small, large)}
        inputs += [(f"generated {n} frames", p.read_bytes()) for n, p in generated.items()]
        inputs.append(
            (f"generated {small} frames, 2 channels, obb", two_channel_stream(folder / "two.json", small).read_bytes())
        )
        spre_table = spre_rows(generated[large], large, args.repeat)  # first: a child inherits the parent's peak
        parse_table = parse_rows(inputs, args.repeat)
    print(f"{'input':44s} {'MB':>6s} {'frames':>7s} {'C ms':>8s} {'msgspec ms':>11s} {'ratio':>6s} {'C MB/s':>7s}")
    for r in parse_table:
        print(
            f"{r['input'][:44]:44s} {r['mb']:6.2f} {r['frames']:7d} {r['c_median_s'] * 1e3:8.2f} "
            f"{r['msgspec_median_s'] * 1e3:11.2f} {r['ratio']:6.1f} {r['mb'] / r['c_median_s']:7.0f}"
        )
    print(f"\nscenegrep spre --compat strem, {large} frames, end to end (median of {args.repeat}):")
    for r in spre_table:
        versus = (
            f" = {r['median_s'] / STREM_SECONDS[large]:.2f} x STREM's {STREM_SECONDS[large]} s"
            if large in STREM_SECONDS
            else ""
        )
        print(
            f"  {r['case'][:48]:48s} {r['parser']:8s} {r['median_s']:6.3f} s ({r['min_s']:.3f}..{r['max_s']:.3f}) "
            f"{r['peak_mb']:6.0f} MB{versus}"
        )
    if args.json:
        args.json.write_text(json.dumps({"parse": parse_table, "spre": spre_table}, indent=1))


if __name__ == "__main__":
    main()
