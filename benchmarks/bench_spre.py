"""SpRE matching: the whole command line, timed against STREM v0.2.0's published numbers.

Writes its own deterministic synthetic STREM JSON streams (one channel, 0-6 axis-aligned
boxes per frame over the classes car, pedestrian, bus, truck; as docs/strem-reference.md
§6 describes STREM's benchmark), then times ``scenegrep spre --compat strem QUERY FILE``
end to end (process start, import, parse, match, print) for the queries of §6 at 20k and
100k frames, the pathological ``[[:car:]]*[[:bus:]]`` offline and ``[[:car:]]*`` online over
all-car streams of growing length (linear time), and online matching over an endless feed
on standard input (one document per frame: constant memory). Each command runs
``--repeat`` times; the table shows the median wall time (and its min..max), frames per
second at the median, the median peak resident memory and the number of matches.

    python benchmarks/bench_spre.py [--repeat 5] [--quick] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CLASSES = ("car", "pedestrian", "bus", "truck")
QUERIES = [
    ("parse only", "[[:zzz:]]", False),
    ("atom", "[[:car:]]", False),
    ("atom online", "[[:car:]]", True),
    ("and range", "[[:car:] & [:pedestrian:]]{2,5}", False),
    ("and range online", "[[:car:] & [:pedestrian:]]{2,5}", True),
    ("overlap star", "[NE([:car:] & [:pedestrian:])]*", False),
    ("exists metric", "[E(v := [:car:])(@area(v) > 30000.0 & @x(v) < 700.0)]", False),
    ("forall distance", "[A(v := [:car:], p := [:pedestrian:])(@dist(v, p) > 500.0)]", False),
    ("star then", "[[:car:]]*[[:pedestrian:]]", False),
    ("star then online", "[[:car:]]*[[:pedestrian:]]", True),
]
STREM_SECONDS = {20_000: 0.30, 100_000: 1.65}
"""STREM v0.2.0 on a 2-core box (docs/strem-reference.md §6 and docs/PRODUCT.md): about 0.3 s per
20k frames on typical queries; 1.65 s and 254 MB per 100k frames; 11.8 s for the pathological queries
at 10k all-car frames."""
STREM_MB_100K = 254
STREM_PATHOLOGICAL_10K = 11.8


def frame(index: int, rng: random.Random, classes: tuple[str, ...], boxes: tuple[int, int]) -> dict:
    annotations = [
        {
            "class": rng.choice(classes),
            "score": round(rng.random(), 3),
            "bbox": {
                "type": "@stremf/bbox/aabb",
                "region": {
                    "center": {"x": round(rng.uniform(0, 1920), 2), "y": round(rng.uniform(0, 1080), 2)},
                    "dimensions": {"w": round(rng.uniform(10, 400), 2), "h": round(rng.uniform(10, 400), 2)},
                },
            },
        }
        for _ in range(rng.randint(*boxes))
    ]
    return {
        "index": index,
        "samples": [
            {
                "type": "@stremf/sample/detection",
                "channel": "cam::front",
                "image": {"path": f"images/{index:06d}.png", "dimensions": {"width": 1920, "height": 1080}},
                "annotations": annotations,
            }
        ],
    }


def write_stream(path: Path, n: int, classes: tuple[str, ...] = CLASSES, boxes: tuple[int, int] = (0, 6)) -> Path:
    """A STREM JSON file of ``n`` frames (seeded by n, so every run writes the same bytes)."""
    rng = random.Random(n * 7919 + len(classes))
    with open(path, "w") as out:
        out.write('{"version":"0.2.0","frames":[')
        for i in range(n):
            out.write(("," if i else "") + json.dumps(frame(i, rng, classes, boxes), separators=(",", ":")))
        out.write("]}")
    return path


def scenegrep(*args: str) -> list[str]:
    return [sys.executable, "-m", "scenegrep", *args]


def run(command: list[str], stdin_path: Path | None = None) -> tuple[float, float, int]:
    """(wall seconds, peak resident MB, output lines) of one run of a command."""
    with open(stdin_path or os.devnull, "rb") as stdin:
        start = time.perf_counter()
        process = subprocess.Popen(
            command,
            stdin=stdin,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"},
        )
        out = process.stdout.read() if process.stdout else b""
        _, status, usage = os.wait4(process.pid, 0)
        seconds = time.perf_counter() - start
    if process.stdout:
        process.stdout.close()
    if os.waitstatus_to_exitcode(status) not in (0, 1):
        raise RuntimeError(f"{' '.join(command)} failed")
    return seconds, usage.ru_maxrss / 1024, out.count(b"\n")


def measure(label: str, frames: int, command: list[str], repeat: int, stdin_path: Path | None = None) -> dict:
    runs = [run(command, stdin_path) for _ in range(repeat)]
    seconds = [r[0] for r in runs]
    median = statistics.median(seconds)
    return {
        "case": label,
        "frames": frames,
        "median_s": median,
        "min_s": min(seconds),
        "max_s": max(seconds),
        "frames_per_s": frames / median,
        "peak_mb": statistics.median(r[1] for r in runs),
        "matches": runs[0][2],
    }


def endless_feed(path: Path, n: int) -> Path:
    """``n`` one-frame STREM documents, one per line (the online feed format), all cars."""
    rng = random.Random(n)
    with open(path, "w") as out:
        for i in range(n):
            out.write(
                json.dumps({"version": "0.2.0", "frames": [frame(i, rng, ("car",), (1, 3))]}, separators=(",", ":"))
                + "\n"
            )
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="smaller streams, for a smoke run")
    parser.add_argument("--json", type=Path, help="also write the rows as JSON here")
    args = parser.parse_args()
    sizes = [2_000, 10_000] if args.quick else [20_000, 100_000]
    all_car = [1_000, 2_000] if args.quick else [5_000, 10_000, 20_000, 40_000]
    feeds = [1_000, 4_000] if args.quick else [10_000, 100_000]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for n in sizes:
            path = write_stream(folder / f"typical_{n}.json", n)
            for label, query, online in QUERIES:
                command = scenegrep("spre", "--compat", "strem", *(["--online"] if online else []), query, str(path))
                rows.append(measure(f"{label}: {query}", n, command, args.repeat))
        for n in all_car:
            path = write_stream(folder / f"cars_{n}.json", n, classes=("car",), boxes=(1, 3))
            for label, query, online in (
                ("pathological offline", "[[:car:]]*[[:bus:]]", False),
                ("pathological online", "[[:car:]]*", True),
            ):
                command = scenegrep("spre", "--compat", "strem", *(["--online"] if online else []), query, str(path))
                rows.append(measure(f"{label}: {query}", n, command, args.repeat))
        for n in feeds:
            feed = endless_feed(folder / f"feed_{n}.jsonl", n)
            command = scenegrep("spre", "--compat", "strem", "--online", "[[:car:]]*")
            rows.append(measure("online stdin feed: [[:car:]]*", n, command, max(1, args.repeat // 2), feed))
    print(
        f"{'case':72s} {'frames':>7s} {'median s':>9s} {'min..max s':>13s} {'frames/s':>10s} {'peak MB':>8s} "
        f"{'matches':>8s}"
    )
    for r in rows:
        print(
            f"{r['case'][:72]:72s} {r['frames']:7d} {r['median_s']:9.3f} {r['min_s']:6.3f}..{r['max_s']:<6.3f} "
            f"{r['frames_per_s']:10.0f} {r['peak_mb']:8.1f} {r['matches']:8d}"
        )
    print(
        "\nSTREM v0.2.0 anchors: 20k frames about 0.30 s; 100k frames 1.65 s and 254 MB; pathological at 10k "
        "all-car frames 11.8 s (offline) / 11.5 s (online), quadratic."
    )
    for n in sizes:
        typical = [
            r["median_s"]
            for r in rows
            if r["frames"] == n and "pathological" not in r["case"] and "feed" not in r["case"]
        ]
        if n in STREM_SECONDS:
            print(
                f"{n} frames: slowest typical query {max(typical):.3f} s = {max(typical) / STREM_SECONDS[n]:.2f} "
                f"x STREM's {STREM_SECONDS[n]} s"
            )
    peaks = [r["peak_mb"] for r in rows if r["frames"] == 100_000 and "feed" not in r["case"]]
    if peaks:
        print(
            f"100k frames: largest peak memory {max(peaks):.0f} MB = {max(peaks) / STREM_MB_100K:.2f} x STREM's "
            f"{STREM_MB_100K} MB"
        )
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
