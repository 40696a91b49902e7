"""Hand-built labeled frames on the synthetic map of tests/model/maps.py, for scene-query tests.

A frame is a dict ``id -> (class, x, y, heading[, length, width[, vx, vy]])`` (velocity in m/s,
unknown when not given); the object named
``ego`` is the trace's ego. Cars default to 4.5 x 2 m, pedestrians to 0.75 x 0.75 m.
"""

from __future__ import annotations

import dataclasses
import math
import textwrap
from pathlib import Path

import numpy as np
import pyarrow.feather as feather

from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.model.layers import UnknownLayers
from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from tests.model.maps import synthetic_map

MAP = synthetic_map()
SIZES = {"Car": (4.5, 2.0), "Pedestrian": (0.75, 0.75), "Truck": (8.0, 2.5), "Cone": (0.4, 0.4)}
HEADER = "model scenic.domains.driving.model\n"
AV2 = Path(__file__).parents[2].parent / "shared/real_data/av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151"
"""The AV2 forecasting scenario whose speeds and accelerations the kinematics tests check by hand."""


def trace_of(*frames: dict) -> LabelTrace:
    """A trace with one frame per dict (objects may differ between frames)."""
    ids = sorted({oid for frame in frames for oid in frame}, key=lambda o: (o != "ego", o))
    classes = {oid: frame[oid][0] for frame in frames for oid in frame}
    rows = []
    for f, frame in enumerate(frames):
        for oid, spec in sorted(frame.items(), key=lambda item: ids.index(item[0])):
            category, x, y, heading, *rest = spec
            length, width = rest[:2] or SIZES[category]
            vx, vy = rest[2:] or (math.nan, math.nan)
            rows.append((f, ids.index(oid), x, y, heading, length, width, vx, vy))
    f, o, x, y, h, length, width, vx, vy = (np.array(column) for column in zip(*rows))
    states = StateTable.build(f, o, x, y, h, length=length, width=width, vx=vx, vy=vy)
    objects = ObjectTable.build(ids, [classes[i] for i in ids])
    n = len(frames)
    return LabelTrace.build(
        "hand", np.arange(n), np.arange(n, dtype=float), objects, states, ego="ego" if "ego" in ids else None
    )


def matches(program: str, *frames: dict, **options) -> list[bool]:
    """Which frames match the program (header added), on the synthetic map; its unknown layers
    (sidewalks, shoulders) are taken as everywhere unless ``unknown_layers`` says otherwise."""
    options.setdefault("unknown_layers", UnknownLayers("permissive"))
    query = compile_scene(HEADER + program, "test.scenic", options.pop("visible_distance_compile", None))
    tolerance = Tolerance(options.pop("position", 1e-6), options.pop("heading", 1e-6), options.pop("speed", 1e-6))
    result = query.match(trace_of(*frames), MAP, SceneOptions(tolerance, **options))
    return result.matched.tolist()


def ahead(x: float, y: float, heading: float, distance: float) -> tuple[float, float]:
    """The point ``distance`` metres ahead of (x, y) along a Scenic heading."""
    return x - distance * math.sin(heading), y + distance * math.cos(heading)


def right(x: float, y: float, heading: float, distance: float) -> tuple[float, float]:
    """The point ``distance`` metres to the right of (x, y) for a Scenic heading."""
    return x + distance * math.cos(heading), y + distance * math.sin(heading)


def av2_ego_velocity(log: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (s) and the ego's velocity (vx, vy in m/s, city frame) at each annotation timestamp of
    an AV2 sensor log: central differences of its city positions (one-sided at the ends), read
    from the log's feather files, not through scenegrep."""
    stamps = np.unique(feather.read_table(log / "annotations.feather", columns=["timestamp_ns"])["timestamp_ns"])
    poses = feather.read_table(log / "city_SE3_egovehicle.feather").to_pandas().set_index("timestamp_ns")
    t = (stamps - stamps[0]) / 1e9
    x, y = poses.tx_m.loc[stamps].to_numpy(), poses.ty_m.loc[stamps].to_numpy()
    return t, np.gradient(x, t), np.gradient(y, t)


def drive_stop_go(until: str, objects: str) -> str:
    """The scenario program of the guard tests (header included): behaviour ``Go`` does ``Drive``
    until ``until`` holds, then ``Stop``; ``objects`` are its object statements (and requirements)."""
    behaviours = textwrap.dedent(f"""\
        behavior Drive():
            while True:
                wait
        behavior Stop():
            while True:
                wait
        behavior Go():
            do Drive() until {until}
            do Stop()
        """)
    return HEADER + behaviours + objects


def all_driving(trace: LabelTrace) -> LabelTrace:
    """``trace`` with every state labeled ``Drive`` (and none ``Stop``)."""
    return dataclasses.replace(trace, behaviours=BehaviourLabels.from_sets([{"Drive"}] * len(trace.states)))
