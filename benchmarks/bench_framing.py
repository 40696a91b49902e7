"""Framing alone (issue 18): the bag reader's framing stage (:mod:`scenegrep.readers.ros.framing`)
fed pre-decoded batches, in CPU microseconds per TrackedObjects message.

The bag of ``bench_bag.py --read N`` (N TrackedObjects messages of ``--objects`` objects, one
``/tf`` message per frame) is read and decoded once, in the offline reader's batches of segments
(:func:`~scenegrep.readers.ros.segments.decoded_batches`); they are kept. Then, ``--runs`` times,
a :class:`FrameBuilder` is fed the same batches into one trace as ``read_trace`` makes it; the
CPU time (``time.process_time``) of that is the framing time. ``--lifetime L`` gives each object a new
UUID every L messages (staggered), so the trace has about N * objects / L objects, as a real
log's tracks come and go (default: the same objects throughout, as bench_bag.py writes).
``--coded``: the boxes' ids, classes and frame ids come as :class:`Coded` columns (codes into
names) even where the decoder gives object arrays. ``--profile`` prints the top of a cProfile of one run.

    python benchmarks/bench_framing.py [--read 10000] [--objects 50] [--lifetime 0] [--coded] [--runs 3] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import dataclasses
import json
import os
import pstats
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "benchmarks"))

from bench_bag import write_read_bench  # noqa: E402
from scenegrep.readers.ros import decoders, framing  # noqa: E402
from scenegrep.readers.ros.bag import bag_runs  # noqa: E402
from scenegrep.readers.ros.messages import Boxes, Coded  # noqa: E402
from scenegrep.readers.ros.options import BagOptions  # noqa: E402
from scenegrep.readers.ros.segments import Segment, decoded_batches  # noqa: E402


def churned(boxes: Boxes, lifetime: int, start: int) -> Boxes:
    """``boxes`` (rows in message order, the same count per message) with the k-th object of
    message m (m counted from ``start``) given a UUID of its slot k and its generation
    (m + k * lifetime / per message) // lifetime, formatted as the decoder does."""
    per = len(boxes) // len(boxes.message_stamps)
    slot = np.arange(len(boxes)) % per
    generation = (boxes.message + start + slot * lifetime // per) // lifetime
    raw = np.zeros((len(boxes), 16), dtype=np.uint8)
    raw[:, :8] = slot.astype("<u8").view(np.uint8).reshape(-1, 8)
    raw[:, 8:] = generation.astype("<u8").view(np.uint8).reshape(-1, 8)
    return dataclasses.replace(boxes, id=decoders._uuid_text(raw))


def predecode(path: Path, lifetime: int, coded: bool) -> list[list[Segment]]:
    """The batches of segments of the bag; ``coded``: the boxes' string columns as :class:`Coded`."""
    out, start = [], 0
    for batch in decoded_batches(bag_runs(path, views=True), BagOptions()):
        kept = []
        for segment in batch:
            decoded = segment.decoded
            if lifetime and isinstance(decoded, Boxes):
                decoded = churned(decoded, lifetime, start)
                start += len(segment.log_times)
            if coded and isinstance(decoded, Boxes):
                columns = {c: getattr(decoded, c) for c in ("id", "category", "frame_id")}
                decoded = dataclasses.replace(
                    decoded, **{c: v if isinstance(v, Coded) else Coded.of(v) for c, v in columns.items()}
                )
            kept.append(dataclasses.replace(segment, decoded=decoded))
        out.append(kept)
    return out


def run(batches: list[list[Segment]]) -> tuple[float, object]:
    """CPU seconds of framing the batches into one trace."""
    start = time.process_time()
    trace = framing.frames(batches, BagOptions(), "bench")
    return time.process_time() - start, trace


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--read", type=int, default=10_000, metavar="N", help="TrackedObjects messages")
    parser.add_argument("--objects", type=int, default=50)
    parser.add_argument("--lifetime", type=int, default=0, help="messages an object id lives (0: forever)")
    parser.add_argument("--coded", action="store_true", help="string columns decoded as Coded")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--profile", action="store_true")
    parser.add_argument("--sort", default="cumulative", help="the profile's order (cumulative, tottime)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.mcap"
        write_read_bench(path, args.read, args.objects)
        batches = predecode(path, args.lifetime, args.coded)
    times = []
    for _ in range(args.runs):
        seconds, trace = run(batches)
        times.append(seconds / args.read * 1e6)
    assert trace.n_frames == args.read, trace.n_frames
    report = {
        "messages": args.read,
        "objects_per_message": args.objects,
        "lifetime": args.lifetime,
        "coded": args.coded,
        "objects": trace.n_objects,
        "states": len(trace.states),
        "load_average": os.getloadavg()[0],
        "framing_cpu_us_per_message": round(statistics.median(times), 2),
        "each_run": [round(t, 2) for t in times],
    }
    print(json.dumps(report, indent=2))
    if args.profile:
        profile = cProfile.Profile()
        profile.runcall(run, batches)
        pstats.Stats(profile).sort_stats(args.sort).print_stats(35)


if __name__ == "__main__":
    main()
