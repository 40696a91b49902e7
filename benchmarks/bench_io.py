"""Load time per input format, and frames per second.

Reads every real recording in ../shared/real_data, a synthetic STREM JSON stream the
script writes itself (20,000 frames, 0-6 boxes per frame, 4 classes) and the
scenegrep Parquet copy of each, ``--repeat`` times each (after one warm-up read that
pays for imports and caches), and prints the median time, the spread and the frames
per second. Maps are timed separately (Parquet-cached OpenDRIVE included).

    python benchmarks/bench_io.py [--repeat 5] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from functools import partial
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from timing import repeated_seconds  # noqa: E402
from scenegrep import readers  # noqa: E402
from scenegrep.readers.trace_parquet import read_trace as read_parquet  # noqa: E402
from scenegrep.writers import write_trace_parquet  # noqa: E402
from tests.readers.real_inputs import REAL_TRACES  # noqa: E402

SHARED = REPO.parent / "shared"


def synthetic_strem(path: Path, n_frames: int, seed: int = 0) -> Path:
    """A STREM JSON stream of ``n_frames`` frames, 0-6 random boxes each over 4 classes."""
    rng = np.random.default_rng(seed)
    classes = ["car", "pedestrian", "bus", "truck"]
    frames = []
    for i in range(n_frames):
        annotations = [
            {
                "class": classes[rng.integers(4)],
                "score": round(float(rng.random()), 3),
                "bbox": {
                    "type": "@stremf/bbox/aabb",
                    "region": {
                        "center": {
                            "x": round(float(rng.uniform(0, 1920)), 2),
                            "y": round(float(rng.uniform(0, 1080)), 2),
                        },
                        "dimensions": {
                            "w": round(float(rng.uniform(10, 400)), 2),
                            "h": round(float(rng.uniform(10, 400)), 2),
                        },
                    },
                },
            }
            for _ in range(rng.integers(0, 7))
        ]
        frames.append(
            {
                "index": i,
                "samples": [
                    {
                        "type": "@stremf/sample/detection",
                        "channel": "cam::front",
                        "image": {"path": f"{i:06d}.png", "dimensions": {"width": 1920, "height": 1080}},
                        "annotations": annotations,
                    }
                ],
            }
        )
    path.write_text(json.dumps({"version": "0.2.0", "frames": frames}))
    return path


def row(label: str, fmt: str, frames: int, times: list[float]) -> dict:
    median = statistics.median(times)
    return {
        "input": label,
        "format": fmt,
        "frames": frames,
        "median_s": median,
        "min_s": min(times),
        "max_s": max(times),
        "frames_per_s": frames / median if median > 0 else float("inf"),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", type=Path, help="also write the rows as JSON here")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp_dir = Path(tmp)
        inputs = [(SHARED / "real_data" / rel, fmt) for rel, fmt in REAL_TRACES]
        inputs.append((synthetic_strem(tmp_dir / "synthetic_20k.json", 20_000), "strem-json"))
        for k, (path, fmt) in enumerate(inputs):
            traces = list(readers.read_traces(path, fmt))
            frames = sum(t.n_frames for t in traces)
            rows.append(
                row(
                    path.name,
                    fmt,
                    frames,
                    repeated_seconds(partial(lambda p, f: list(readers.read_traces(p, f)), path, fmt), args.repeat),
                )
            )
            parquet = write_trace_parquet(traces[0], tmp_dir / f"{k}.parquet")
            rows.append(
                row(
                    path.name,
                    "scenegrep-parquet",
                    traces[0].n_frames,
                    repeated_seconds(partial(read_parquet, parquet), args.repeat),
                )
            )
        maps = [(SHARED / "maps" / "Town01.xodr", "opendrive"), (SHARED / "maps" / "Town06.xodr", "opendrive")]
        maps += [
            (SHARED / "real_data" / rel, fmt) for rel, fmt in REAL_TRACES[:1] + REAL_TRACES[3:4] + REAL_TRACES[-3:-2]
        ]
        for path, fmt in maps:
            source = path if fmt == "opendrive" else next(readers.read_traces(path)).map_source

            def load(source=source) -> object:
                readers._read_map_cached.cache_clear()
                return readers.read_map(source)

            road_map = load()
            rows.append(
                {**row(path.name, f"map ({fmt})", 0, repeated_seconds(load, args.repeat)), "lanes": len(road_map.lanes)}
            )
    print(f"{'input':58s} {'format':24s} {'frames':>7s} {'median ms':>10s} {'min..max ms':>16s} {'frames/s':>10s}")
    for r in rows:
        fps = f"{r['frames_per_s']:10.0f}" if r["frames"] else f"{'-':>10s}"
        spread = f"{r['min_s'] * 1e3:.1f}..{r['max_s'] * 1e3:.1f}"
        print(
            f"{r['input'][:58]:58s} {r['format']:24s} {r['frames']:7d} {r['median_s'] * 1e3:10.1f} {spread:>16s} {fps}"
        )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
