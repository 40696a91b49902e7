"""Bag benchmarks (issue 18): per-frame online latency of ``--follow``; the bag reader's read throughput
(messages per second, TrackedObjects with 50 objects per message) is the reader's section, to come.

**Online latency.** A writer thread appends an MCAP file frame by frame at ``--rate`` frames per
second (unchunked, as a live recorder writes) while ``scenegrep spre --follow FILE PATTERN`` runs in
a subprocess, with a pattern that every frame matches, so every frame prints one line. The frames:

* ``--source strem``: one STREM JSON document of ``--boxes`` image boxes per frame (a
  ``strem/Document`` channel), pattern ``[[:car:]]+``;
* ``--source ros``: Autoware ``TrackedObjects`` + ``/tf`` of the AV2 log 7fab2350 (``../shared``),
  written by the tests' writer (tests/readers/ros_writer.py), ``--frames`` at most 156, pattern
  ``[[:car:]]`` over top-down boxes.

Per frame:

* external: from the writer's last byte of the frame's last message to the arrival of its line
  here (the follower's polling, 10 ms at most, decoding, the query, the pipe), both on
  ``time.monotonic()``, the system-wide monotonic clock;
* internal: scenegrep's own ``--latency`` line (from the read of the frame's last message to its
  match printed).

Median and p99 in milliseconds; the first ``--warm-up`` frames are not counted externally (the
follower's first decode and query compile; the maximum over all frames is reported). The frames'
count must equal the lines' (FAILED otherwise).

    python benchmarks/bench_bag.py [--source strem|ros] [--frames 300] [--rate 30] [--boxes 20] [--json results.json]
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
sys.path.insert(0, str(REPO / "src"))

from scenegrep.readers.mcap_follow import RawMessage, follow_mcap  # noqa: E402

PATTERN = "[[:car:]]+"
AV2 = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"


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


def strem_frames(frames: int, boxes: int) -> list[list[RawMessage]]:
    """Each frame's messages: one document."""
    return [
        [RawMessage("/detections", "strem/Document", "", b"", "json", k * 10**8, frame_document(k, boxes))]
        for k in range(frames)
    ]


def ros_frames(frames: int) -> list[list[RawMessage]]:
    """Each frame's messages as the tests' writer writes the AV2 log: /tf and TrackedObjects."""
    sys.path.insert(0, str(REPO / "tests" / "readers"))
    from ros_writer import write_tracked

    from scenegrep import readers

    trace = readers.read_trace(REPO.parent / "shared" / "real_data" / AV2).slice_frames(0, frames)
    grouped: list[list] = []
    with tempfile.TemporaryDirectory() as folder:
        write_tracked(trace, Path(folder) / "whole.mcap")
        for message in follow_mcap(Path(folder) / "whole.mcap"):
            if message.topic == "/tf":
                grouped.append([])
            grouped[-1].append(message)
    return grouped


def write_live(path: Path, frames: list[list], rate: float, start: threading.Event, times: list) -> None:
    """Append the frames' messages to ``path`` at ``rate`` frames per second once ``start`` is set;
    ``times`` gets each frame's write time (monotonic seconds, after its last message)."""
    buffer = io.BytesIO()
    writer = Writer(buffer, compression=CompressionType.NONE, use_chunking=False)
    writer.start("", "bench_bag")
    channels: dict[str, int] = {}
    fd = os.open(path, os.O_WRONLY | os.O_APPEND)

    def flush() -> None:
        os.write(fd, buffer.getvalue())
        buffer.seek(0)
        buffer.truncate()

    flush()
    start.wait()
    due = time.monotonic()
    for messages in frames:
        for message in messages:
            if message.topic not in channels:
                schema = writer.register_schema(message.schema_name, message.schema_encoding, message.schema_data)
                channels[message.topic] = writer.register_channel(message.topic, message.message_encoding, schema)
            writer.add_message(channels[message.topic], log_time=message.log_time, data=message.data, publish_time=0)
            flush()
        times.append(time.monotonic())
        due += 1 / rate
        time.sleep(max(0.0, due - time.monotonic()))
    writer.finish()
    flush()
    os.close(fd)


def online_latency(frames: list[list], pattern: list[str], rate: float, warm_up: int) -> dict:
    """The online latency section (see the module docstring)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "live.mcap"
        path.write_bytes(b"")
        start = threading.Event()
        written: list[float] = []
        writer = threading.Thread(target=write_live, args=(path, frames, rate, start, written))
        writer.start()
        while path.stat().st_size == 0:
            time.sleep(0.01)
        command = [sys.executable, "-m", "scenegrep", "spre", *pattern, "--follow", str(path), "--latency"]
        env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        arrivals: list[float] = []
        reader = threading.Thread(target=lambda: arrivals.extend(time.monotonic() for _ in process.stdout))
        reader.start()
        wait_until_open(process.pid, path)
        start.set()
        writer.join()
        process.wait(120)
        reader.join()
        internal = process.stderr.read().strip()
    if len(arrivals) != len(frames):
        return {"status": f"FAILED: {len(arrivals)} lines for {len(frames)} frames", "stderr": internal}
    every = (np.array(arrivals) - np.array(written)) * 1000
    external = every[warm_up:]
    return {
        "frames": len(frames),
        "rate_hz": rate,
        "external_median_ms": round(float(statistics.median(external)), 2),
        "external_p99_ms": round(float(np.percentile(external, 99)), 2),
        "external_max_ms": round(float(external.max()), 2),
        "first_frame_ms": round(float(every[0]), 2),
        "internal": internal.splitlines()[-1].removeprefix("scenegrep: "),
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
    parser.add_argument("--source", choices=["strem", "ros"], default="strem")
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--rate", type=float, default=30.0, help="frames per second written")
    parser.add_argument("--boxes", type=int, default=20, help="boxes per frame (strem)")
    parser.add_argument("--warm-up", type=int, default=5, help="first frames not counted")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    if args.source == "strem":
        frames, pattern = strem_frames(args.frames, args.boxes), [PATTERN]
        details = {"source": "STREM documents", "boxes_per_frame": args.boxes}
    else:
        frames, pattern = ros_frames(args.frames), ["--space", "topdown", "[[:car:]]"]
        details = {"source": "TrackedObjects + /tf (AV2 7fab2350)"}
    report = {"online_latency": details | online_latency(frames, pattern, args.rate, args.warm_up)}
    print(json.dumps(report, indent=2))
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
