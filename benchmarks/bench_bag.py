"""Bag benchmarks (issue 18): per-frame online latency of ``--follow``, and the bag reader's read
throughput (``--read N``).

**Read throughput.** A bag of N ``autoware_perception_msgs/TrackedObjects`` messages of
``--objects`` objects each (every field written, covariances included: about 1.1 kB per object;
boxes in ``base_link``), one ``/tf`` message per frame, zstd chunks, is read by the ``ros-bag``
reader into one trace; messages per second (TrackedObjects messages over the whole read), and
the MCAP stream alone (records read and decompressed, nothing decoded) for comparison, each the
median of ``--runs`` runs (alternated, so both see the same load); the ratio of the two, the CPU
time per message (``time.process_time``) and the load average, since the machine may be shared.

**Online latency.** A writer thread appends an MCAP file frame by frame at ``--rate`` frames per
second (unchunked, as a live recorder writes) while ``scenegrep spre --follow FILE PATTERN`` runs in
a subprocess, with a pattern that every frame matches, so every frame prints one line. The frames:

* ``--source strem``: one STREM JSON document of ``--boxes`` image boxes per frame (a
  ``strem/Document`` channel), pattern ``[[:car:]]+``;
* ``--source ros``: Autoware ``TrackedObjects`` + ``/tf`` of the AV2 log 7fab2350 (``../shared``),
  written by :mod:`scenegrep.writers.ros_bag`, ``--frames`` at most 156, pattern
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

    python benchmarks/bench_bag.py [--source strem|ros] [--frames 300] [--rate 30] [--boxes 20]
        [--read 100000] [--objects 50] [--runs 3] [--no-latency] [--json results.json]
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
sys.path.insert(0, str(REPO))

from scenegrep.readers.mcap_follow import RawMessage, follow_mcap  # noqa: E402
from tests.live_writer import has_open  # noqa: E402

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
    """Each frame's messages as scenegrep.writers.ros_bag writes the AV2 log: /tf and TrackedObjects."""
    from scenegrep import readers
    from scenegrep.writers.ros_bag import write_tracked

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
        if not has_open(process.pid, path, 60):
            raise SystemExit("the follower never opened the file")
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


def write_read_bench(path: Path, messages: int, objects: int) -> int:
    """Write the read-throughput bag (see the module docstring) to ``path``; the bytes of one
    TrackedObjects message."""
    from mcap_ros2._dynamic import serialize_dynamic

    from scenegrep.writers.ros_bag import ORIGIN_NS
    from scenegrep.writers.ros_messages import Box, schema, tracked_object

    def encoder(name: str):
        full = name.replace("/", "/msg/")
        return serialize_dynamic(full, schema(name))[full], schema(name)

    boxes = [
        Box(
            f"object-{k}",
            "car",
            "car",
            {"x": 5.0 * k, "y": 2.0, "z": 0.0},
            0.1 * k,
            {"x": 4.5, "y": 1.9, "z": 1.6},
            {"x": 3.0, "y": 0.0, "z": 0.0},
        )
        for k in range(objects)
    ]
    encode_objects, objects_schema = encoder("autoware_perception_msgs/TrackedObjects")
    encode_tf, tf_schema = encoder("tf2_msgs/TFMessage")
    header = {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": "base_link"}
    template = bytearray(encode_objects({"header": header, "objects": [tracked_object(b) for b in boxes]}))
    identity = {"translation": {"x": 0.0, "y": 0.0, "z": 0.0}, "rotation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}}
    link = {"header": {**header, "frame_id": "map"}, "child_frame_id": "base_link", "transform": identity}
    tf_template = bytearray(encode_tf({"transforms": [link]}))
    with open(path, "wb") as handle:
        writer = Writer(handle, compression=CompressionType.ZSTD)
        writer.start("ros2", "bench_bag")
        objects_channel = writer.register_channel(
            "/objects",
            "cdr",
            writer.register_schema("autoware_perception_msgs/msg/TrackedObjects", "ros2msg", objects_schema.encode()),
        )
        tf_channel = writer.register_channel(
            "/tf", "cdr", writer.register_schema("tf2_msgs/msg/TFMessage", "ros2msg", tf_schema.encode())
        )
        for i in range(messages):
            stamp = ORIGIN_NS + i * 100_000_000
            sec, nanosec = (stamp // 10**9).to_bytes(4, "little"), (stamp % 10**9).to_bytes(4, "little")
            template[4:12] = tf_template[8:16] = sec + nanosec  # header stamps (the tf one after its count)
            writer.add_message(tf_channel, stamp, bytes(tf_template), stamp)
            writer.add_message(objects_channel, stamp, bytes(template), stamp)
        writer.finish()
    return len(template)


def read_throughput(messages: int, objects: int, runs: int) -> dict:
    """Messages per second read by the ros-bag reader (see the module docstring): medians of
    ``runs`` runs."""
    from scenegrep.readers.ros.bag import bag_messages
    from scenegrep.readers.ros.reader import read_trace

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.mcap"
        size = write_read_bench(path, messages, objects)
        stream, read, cpu = [], [], []
        for _ in range(runs):  # alternated, so both see the same load of a shared machine
            start = time.perf_counter()
            records = sum(1 for _ in bag_messages(path))
            stream.append(records / (time.perf_counter() - start))
            start, start_cpu = time.perf_counter(), time.process_time()
            trace = read_trace(path)
            read.append(messages / (time.perf_counter() - start))
            cpu.append((time.process_time() - start_cpu) / messages * 1e6)
            assert trace.n_frames == messages and len(trace.states) == messages * (objects + 1)
    return {
        "messages": messages,
        "objects_per_message": objects,
        "bytes_per_message": size,
        "runs": runs,
        "load_average": os.getloadavg()[0],
        "mcap_stream_messages_per_s": round(statistics.median(stream)),
        "read_messages_per_s": round(statistics.median(read)),
        "read_over_stream": round(statistics.median(r / s for r, s in zip(read, stream)), 4),
        "read_cpu_us_per_message": round(statistics.median(cpu), 2),
        "read_messages_per_s_each_run": [round(r) for r in read],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", choices=["strem", "ros"], default="strem")
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--rate", type=float, default=30.0, help="frames per second written")
    parser.add_argument("--boxes", type=int, default=20, help="boxes per frame (strem)")
    parser.add_argument("--warm-up", type=int, default=5, help="first frames not counted")
    parser.add_argument("--read", type=int, default=0, metavar="N", help="TrackedObjects messages read (0: skip)")
    parser.add_argument("--objects", type=int, default=50, help="objects per TrackedObjects message")
    parser.add_argument("--runs", type=int, default=3, help="read runs (medians reported)")
    parser.add_argument("--no-latency", action="store_true", help="skip the online latency")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    report = {}
    if not args.no_latency:
        if args.source == "strem":
            frames, pattern = strem_frames(args.frames, args.boxes), [PATTERN]
            details = {"source": "STREM documents", "boxes_per_frame": args.boxes}
        else:
            frames, pattern = ros_frames(args.frames), ["--space", "topdown", "[[:car:]]"]
            details = {"source": "TrackedObjects + /tf (AV2 7fab2350)"}
        report["online_latency"] = details | online_latency(frames, pattern, args.rate, args.warm_up)
    if args.read:
        report["read_throughput"] = read_throughput(args.read, args.objects, args.runs)
    print(json.dumps(report, indent=2))
    if args.json:
        args.json.write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
