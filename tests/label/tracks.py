"""Hand-built tracks on the synthetic map of tests/model/maps.py, for labeller tests.

A track is given by positions sampled every ``DT`` seconds; headings default to the direction
of motion (Scenic convention) and velocities are left unknown, so the labeller derives them.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from scenegrep.model import LabelTrace, LaneNeighbour, ObjectTable, RoadMap, StateTable
from scenegrep.model.geometry import heading_of_vector
from tests.model.maps import synthetic_map

DT = 0.1


def neighbour_map() -> RoadMap:
    """The synthetic map with n2 the same-direction right neighbour of n1 (and n1 its left)."""
    road_map = synthetic_map()
    lanes = []
    for lane in road_map.lanes:
        if lane.id == "n1":
            lane = replace(lane, right=LaneNeighbour("n2", True), left=LaneNeighbour("s1", False))
        elif lane.id == "n2":
            lane = replace(lane, left=LaneNeighbour("n1", True))
        lanes.append(lane)
    return replace(road_map, lanes=tuple(lanes))


def motion_heading(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Direction of motion along a sampled path (the last step repeated at the end)."""
    dx, dy = np.diff(x, append=2 * x[-1] - x[-2]), np.diff(y, append=2 * y[-1] - y[-2])
    return heading_of_vector(dx, dy)


def trace_of(*tracks: tuple[str, np.ndarray, np.ndarray, np.ndarray | None]) -> LabelTrace:
    """A trace of ``(class, x, y, heading or None)`` tracks, all starting at frame 0."""
    frames, objects, xs, ys, headings = [], [], [], [], []
    for k, (_, x, y, heading) in enumerate(tracks):
        frames.append(np.arange(len(x)))
        objects.append(np.full(len(x), k))
        xs.append(x)
        ys.append(y)
        headings.append(motion_heading(x, y) if heading is None else heading)
    n_frames = max(len(x) for _, x, _, _ in tracks)
    states = StateTable.build(
        np.concatenate(frames),
        np.concatenate(objects),
        np.concatenate(xs),
        np.concatenate(ys),
        np.concatenate(headings),
        length=np.full(sum(map(len, xs)), 4.5),
        width=np.full(sum(map(len, xs)), 2.0),
    )
    ids = [f"o{k}" for k in range(len(tracks))]
    objects_table = ObjectTable.build(ids, [category for category, *_ in tracks])
    return LabelTrace.build("hand", np.arange(n_frames), np.arange(n_frames) * DT, objects_table, states)


def sets_of(trace: LabelTrace, object_row: int = 0) -> list[frozenset[str]]:
    """The label sets of one object, frame by frame."""
    rows = np.flatnonzero(trace.states.object == object_row)
    sets = trace.behaviours.sets()
    return [sets[i] for i in rows]
