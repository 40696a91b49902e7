"""Bag benchmarks (issue 18): per-frame online latency of ``--follow``; the bag reader's read throughput
(messages per second, TrackedObjects with 50 objects per message) is the reader's section, to come.

**Online latency.** A writer thread appends an MCAP file one message per frame at ``--rate`` Hz
(unchunked, as a live recorder writes; each message one STREM JSON document of ``--boxes`` boxes
on a ``strem/Document`` channel) while ``scenegrep spre --follow FILE '[[:car:]]+'`` runs in a
subprocess: every frame holds a car, so every frame ends a match and prints one line. Per frame:

* external: from the writer's last byte of the frame's message to the arrival of its line here
  (the follower's polling, 10 ms at most, decoding, the query, the pipe), both on
  ``time.monotonic()``, the system-wide monotonic clock;
* internal: scenegrep's own ``--latency`` line (from the read of the frame's last message to its
  match printed).

Median and p99 in milliseconds; the first ``--warm-up`` frames are not counted (the follower's first
decode and query compile). The frames' count must equal the lines' (FAILED otherwise).

    python benchmarks/bench_bag.py [--frames 300] [--rate 30] [--boxes 20] [--json results.json]
"""

from __future__ import annotations

import argparse
import io
import json
import os
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer

REPO = Path(__file__).resolve().parents[1]
PATTERN = "[[:car:]]+"


def frame_document(index: int, boxes: int) -> bytes:
    """One STREM frame of ``boxes`` boxes (the first a car) as a STREM JSON document."""
    kinds = ["car", "pedestrian", "truck", "bicycle"]
    annotations = [
        {
            "class": kinds[k % len(kinds)],
            "score": 0.9,
            "bbox": {
                "type": "@stremf/bbox/aabb",
                "region": {"center": {"x": 20 * k % 640, "y": 11 * k % 480}, "dimensions": {"w": 30, "h": 20}},
            },
        }
        for k in range(boxes)
    ]
    sample = {
        "type": "@stremf/sample/detection",
        "channel": "front",
        "image": {"path": f"{index}.png", "dimensions": {"width": 640, "height": 480}},
        "annotations": annotations,
    }
    return json.dumps({"version": "0.2.0", "frames": [{"index": index, "samples": [sample]}]}).encode()


def write_live(path: Path, frames: int, rate: float, boxes: int, start: threading.Event, times: list) -> None:
    """Append the frames' messages to ``path`` at ``rate`` Hz once ``start`` is set; ``times`` gets
    each message's write time (monotonic seconds)."""
    buffer = io.BytesIO()
    writer = Writer(buffer, compression=CompressionType.NONE, use_chunking=False)
    writer.start("", "bench_bag")
    channel = writer.register_channel("/detections", "json", writer.register_schema("strem/Document", "", b""))
    fd = os.open(path, os.O_WRONLY | os.O_APPEND)

    def flush() -> None:
        os.write(fd, buffer.getvalue())
        buffer.seek(0)
        buffer.truncate()

    flush()
    start.wait()
    due = time.monotonic()
    for index in range(frames):
        writer.add_message(channel, log_time=index * 10**6, data=frame_document(index, boxes), publish_time=0)
        flush()
        times.append(time.monotonic())
        due += 1 / rate
        time.sleep(max(0.0, due - time.monotonic()))
    writer.finish()
    flush()
    os.close(fd)


def online_latency(frames: int, rate: float, boxes: int, warm_up: int) -> dict:
    """The online latency section (see the module docstring)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "live.mcap"
        path.write_bytes(b"")
        start = threading.Event()
        written: list[float] = []
        writer = threading.Thread(target=write_live, args=(path, frames, rate, boxes, start, written))
        writer.start()
        while path.stat().st_size == 0:
            time.sleep(0.01)
        command = [sys.executable, "-m", "scenegrep", "spre", PATTERN, "--follow", str(path), "--latency"]
        env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        arrivals: list[float] = []
        reader = threading.Thread(target=lambda: arrivals.extend(time.monotonic() for _ in process.stdout))
        reader.start()
        wait_until_open(process.pid, path)
        start.set()
        writer.join()
        process.wait(60)
        reader.join()
        internal = process.stderr.read().strip()
    if len(arrivals) != frames:
        return {"status": f"FAILED: {len(arrivals)} lines for {frames} frames", "stderr": internal}
    external = (np.array(arrivals) - np.array(written))[warm_up:] * 1000
    return {
        "frames": frames,
        "rate_hz": rate,
        "boxes_per_frame": boxes,
        "external_median_ms": round(float(statistics.median(external)), 2),
        "external_p99_ms": round(float(np.percentile(external, 99)), 2),
        "external_max_ms": round(float(external.max()), 2),
        "internal": internal.removeprefix("scenegrep: "),
    }


def wait_until_open(pid: int, path: Path) -> None:
    """Until process ``pid`` has ``path`` open (its query is compiled and it reads the file)."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            if any(Path(f"/proc/{pid}/fd/{fd}").resolve() == path.resolve() for fd in os.listdir(f"/proc/{pid}/fd")):
                return
        except OSError:
            pass
        time.sleep(0.01)
    raise SystemExit("the follower never opened the file")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--rate", type=float, default=30.0, help="frames per second written")
    parser.add_argument("--boxes", type=int, default=20, help="boxes per frame")
    parser.add_argument("--warm-up", type=int, default=5, help="first frames not counted")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    report = {"online_latency": online_latency(args.frames, args.rate, args.boxes, args.warm_up)}
    print(json.dumps(report, indent=2))
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
