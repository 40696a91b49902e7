"""Behaviour labelling throughput: observations (objects x frames) labelled per second.

Part 1: every real recording in ../shared/real_data (its own map read beforehand, not timed):
median of ``--repeat`` runs of ``label_trace`` after one warm-up, observations per second.
Part 2: scaling with the number of observations: one nuScenes scene (scene-0061, 22,611
observations) with its objects replicated k times (new ids, same tracks), k = 1, 2, 4, 8, 16;
the time per observation should stay flat (linear time).

    python benchmarks/bench_label.py [--repeat 5] [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from timing import median_seconds  # noqa: E402
from scenegrep import readers  # noqa: E402
from scenegrep.label import label_trace  # noqa: E402
from scenegrep.model import LabelTrace, ObjectTable, StateTable  # noqa: E402
from tests.readers.real_inputs import REAL_TRACES  # noqa: E402

SHARED = REPO.parent / "shared"
SCENE = SHARED / "real_data" / "nuscenes_mini_scenarionet" / "sd_nuscenes_v1.0-mini_scene-0061.pkl"


def replicated(trace: LabelTrace, k: int) -> LabelTrace:
    """``trace`` with every object present ``k`` times (ids suffixed #1..#k)."""
    n = trace.n_objects
    ids = [f"{i}#{c}" for c in range(k) for i in trace.objects.id.tolist()]
    objects = ObjectTable.build(ids, np.tile(trace.objects.category, k).tolist())
    columns = {name: np.tile(values, k) for name, values in trace.states.columns().items()}
    columns["object"] = np.concatenate([trace.states.object + c * n for c in range(k)])
    states = StateTable(**columns)
    return LabelTrace.build(trace.name, trace.frame_index, trace.frame_time, objects, states, lane_ids=trace.lane_ids)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args()
    results: dict = {"recordings": [], "scaling": []}
    print(f"{'recording':58} {'obs':>7} {'ms':>8} {'obs/s':>10}")
    for relative, fmt in REAL_TRACES:
        path = SHARED / "real_data" / relative
        for trace in readers.read_traces(path, fmt):
            road_map = readers.read_map(trace.map_source) if trace.map_source else None
            seconds = median_seconds(lambda trace=trace, road_map=road_map: label_trace(trace, road_map), args.repeat)
            n = len(trace.states)
            results["recordings"].append(
                {"recording": f"{relative}#{trace.name}", "observations": n, "seconds": seconds}
            )
            print(f"{(relative + '#' + trace.name)[-58:]:58} {n:7d} {seconds * 1e3:8.1f} {n / seconds:10.0f}")
    total_n = sum(r["observations"] for r in results["recordings"])
    total_s = sum(r["seconds"] for r in results["recordings"])
    print(f"all recordings: {total_n} observations in {total_s:.2f} s, {total_n / total_s:.0f} observations/s")
    trace = readers.read_trace(SCENE)
    road_map = readers.read_map(trace.map_source)
    print(f"\nscaling (scene-0061 objects replicated k times)\n{'k':>3} {'obs':>8} {'s':>7} {'us/obs':>7}")
    for k in (1, 2, 4, 8, 16):
        big = replicated(trace, k)
        seconds = median_seconds(lambda big=big: label_trace(big, road_map), max(1, args.repeat // 2))
        n = len(big.states)
        results["scaling"].append({"k": k, "observations": n, "seconds": seconds})
        print(f"{k:3d} {n:8d} {seconds:7.3f} {seconds / n * 1e6:7.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
