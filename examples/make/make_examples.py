"""Writes the small example inputs the README's commands name, from the project's own data:

- ``examples/trace.json``: a scenegrep JSON trace, frames 0-29 (3 s) of the sample trace
  ``fig1_lane_change-000`` (the ego changes lanes past a standing car), on one line (so
  ``scenario --online`` reads it from stdin too) and without a ``map`` entry: its map is
- ``examples/map.parquet``: a scenegrep Parquet map, Town06 cropped to 150 m around the trace;
- ``examples/scenes.json``: 5 scenes Scenic 3.1.1 sampled from
  ``examples/ground_truth/car_ahead.scenic`` on Town01 (seed 3), one per frame, without a map
  entry (the README gives ``--map``);
- ``examples/stream.json``: a STREM JSON v0.2.0 stream of 60 frames (6 s at 10 Hz): the boxes a
  pinhole front camera on the ego (1600 x 900 px, focal length 1000 px, 1.5 m above the ground)
  sees in one simulated run of ``examples/make/street.scenic`` (Scenic's Newtonian simulator,
  seed 0): the car ahead (class ``car``) and a pedestrian walking ahead (``pedestrian``);
- ``examples/stream.mcap`` and ``examples/trace.mcap``: the same as MCAP files, one JSON document
  per frame and message (schemas ``strem/Document`` and ``scenegrep/Trace``, topics ``/camera``
  and ``/trace``, frames 0.1 s apart), what ``--follow`` reads while a recorder writes it;
- ``examples/drive.mcap``: the whole sample trace ``fig1_lane_change-000`` (15 s at 10 Hz) as an
  Autoware stack logs it (:mod:`scenegrep.writers.ros_bag`): ``TrackedObjects`` in the ego's
  frame ``base_link`` and the ego's pose in the map frame on ``/tf``, stamped from 2023-11-14;
- ``examples/lanelet2_map.osm``: ``examples/map.parquet``'s map (which holds the whole trace) as a
  Lanelet2 map, Autoware style (:mod:`scenegrep.writers.lanelet2`): lanes, shoulders and curbs.

Run from the repository root: ``python examples/make/make_examples.py`` (Scenic is needed for
the last two). The same Scenic version and seeds give the same files.
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from scenegrep import readers
from scenegrep.model import LabelTrace
from scenegrep.synth.scenic_scenes import sample_scenes
from scenegrep.synth.simulate import simulate_runs
from scenegrep.writers.lanelet2 import write_road_map_lanelet2
from scenegrep.writers.ros_bag import write_tracked
from scenegrep.writers.trace_json import trace_document
from scenegrep.writers.trace_parquet import write_map_parquet

EXAMPLES = Path(__file__).resolve().parents[1]
TOWN01 = EXAMPLES / "sample" / "Town01.xodr"
WIDTH, HEIGHT, FOCAL, CAMERA_HEIGHT = 1600, 900, 1000.0, 1.5
MAX_DEPTH = 30.0


def write_trace_and_map(out: Path = EXAMPLES) -> None:
    """``trace.json`` (frames 0-29 of a sample trace, no map entry) and ``map.parquet`` in ``out``."""
    trace = readers.read_trace(EXAMPLES / "sample" / "fig1_lane_change-000.parquet").slice_frames(0, 30)
    road_map = readers.read_map(trace.map_source)
    x, y = trace.states.x, trace.states.y
    centre = ((x.min() + x.max()) / 2, (y.min() + y.max()) / 2)
    write_map_parquet(road_map.crop(*centre, 150.0), out / "map.parquet")
    document = trace_document(replace(trace, name="trace", map_source=None))
    (out / "trace.json").write_text(json.dumps(document, separators=(",", ":")) + "\n")


def write_scenes() -> None:
    """``scenes.json``: scenes Scenic sampled from the Fig. 3 ground-truth program, no map entry."""
    scenes = sample_scenes(EXAMPLES / "ground_truth" / "car_ahead.scenic", 5, map_path=TOWN01, seed=3)
    document = trace_document(replace(scenes, name="scenes", map_source=None))
    (EXAMPLES / "scenes.json").write_text(json.dumps(document, indent=1) + "\n")


def camera_boxes(trace: LabelTrace, frame: int) -> list[dict]:
    """The image boxes of every object but the ego at ``frame`` position, as STREM annotations:
    each object's 3-D box (its labeled footprint, from the ground to its height) projected by a
    pinhole camera on the ego looking along its heading, the bounding rectangle of the corners,
    clipped to the image; objects behind the camera, beyond 30 m or outside the image are left out."""
    states = trace.states
    rows = np.flatnonzero(states.frame == frame)
    ego = rows[states.object[rows] == trace.object_index(trace.ego)][0]
    cx, cy, heading = states.x[ego], states.y[ego], states.heading[ego]
    forward = np.array([-np.sin(heading), np.cos(heading)])
    left = np.array([-np.cos(heading), -np.sin(heading)])
    annotations = []
    for row in rows[rows != ego].tolist():
        h = states.heading[row]
        along = np.array([-np.sin(h), np.cos(h)]) * states.length[row] / 2
        across = np.array([-np.cos(h), -np.sin(h)]) * states.width[row] / 2
        centre = np.array([states.x[row] - cx, states.y[row] - cy])
        corners = np.array([centre + a * along + b * across for a in (-1, 1) for b in (-1, 1)])
        depth, lateral = corners @ forward, corners @ left
        if depth.min() < 1.0 or depth.min() > MAX_DEPTH:
            continue
        u = WIDTH / 2 - FOCAL * lateral / depth
        top = HEIGHT / 2 - FOCAL * (states.height[row] - CAMERA_HEIGHT) / depth
        bottom = HEIGHT / 2 + FOCAL * CAMERA_HEIGHT / depth
        x0, x1 = max(u.min(), 0.0), min(u.max(), WIDTH)
        y0, y1 = max(top.min(), 0.0), min(bottom.max(), HEIGHT)
        if x1 <= x0 or y1 <= y0:
            continue
        region = {
            "center": {"x": round((x0 + x1) / 2, 1), "y": round((y0 + y1) / 2, 1)},
            "dimensions": {"w": round(x1 - x0, 1), "h": round(y1 - y0, 1)},
        }
        kind = str(trace.objects.category[states.object[row]]).lower()
        annotations.append({"class": kind, "score": 1.0, "bbox": {"type": "@stremf/bbox/aabb", "region": region}})
    return annotations


def write_stream() -> None:
    """``stream.json``: what a front camera sees in one simulated run of ``street.scenic``."""
    (trace,) = simulate_runs(EXAMPLES / "make" / "street.scenic", map_path=TOWN01, runs=1, steps=60, seed=0)
    frames = []
    for f in range(trace.n_frames):
        image = {"path": f"front/{f:04d}.jpg", "dimensions": {"width": WIDTH, "height": HEIGHT}}
        sample = {"type": "@stremf/sample/detection", "channel": "front", "image": image}
        frames.append({"index": f, "samples": [{**sample, "annotations": camera_boxes(trace, f)}]})
    text = json.dumps({"version": "0.2.0", "frames": frames}, indent=1)
    (EXAMPLES / "stream.json").write_text(text + "\n")


def write_drive(out: Path = EXAMPLES) -> None:
    """``drive.mcap`` (a sample trace as an Autoware bag) and ``lanelet2_map.osm`` (``map.parquet``
    as Lanelet2) in ``out``."""
    trace = readers.read_trace(EXAMPLES / "sample" / "fig1_lane_change-000.parquet")
    write_tracked(trace, out / "drive.mcap")
    write_road_map_lanelet2(readers.read_map(EXAMPLES / "map.parquet"), out / "lanelet2_map.osm")


def write_mcap(path: Path, topic: str, schema: str, documents: list[dict]) -> None:
    """``documents`` as the JSON messages of one MCAP channel, 0.1 s apart."""
    from mcap.writer import Writer

    with open(path, "wb") as stream:
        writer = Writer(stream)
        writer.start("", "scenegrep examples")
        channel = writer.register_channel(topic, "json", writer.register_schema(schema, "jsonschema", b""))
        for k, document in enumerate(documents):
            data = json.dumps(document, separators=(",", ":")).encode()
            writer.add_message(channel, log_time=k * 100_000_000, data=data, publish_time=k * 100_000_000)
        writer.finish()


def write_mcaps(out: Path = EXAMPLES) -> None:
    """``stream.mcap`` (``examples/stream.json``'s frames) and ``trace.mcap`` (``examples/trace.json``'s
    frames) in ``out``."""
    stream = json.loads((EXAMPLES / "stream.json").read_text())
    frames = [{"version": stream["version"], "frames": [frame]} for frame in stream["frames"]]
    write_mcap(out / "stream.mcap", "/camera", "strem/Document", frames)
    trace = readers.read_trace(EXAMPLES / "trace.json")
    documents = [trace_document(trace.slice_frames(f, f + 1)) for f in range(trace.n_frames)]
    write_mcap(out / "trace.mcap", "/trace", "scenegrep/Trace", documents)


if __name__ == "__main__":
    write_trace_and_map()
    if "--no-scenic" not in sys.argv:
        write_scenes()
        write_stream()
    write_mcaps()
    write_drive()
