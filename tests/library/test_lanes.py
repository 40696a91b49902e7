"""The lane situations of the real-situation library (examples/queries/real/): lane changes,
same lane ahead, following, N vehicles ahead, overtaking. Each query's answers are checked
against truths computed here with numpy and shapely from the raw recordings (positions,
headings, times and the map's lanes: ids, polygons, centrelines, successors, left/right
neighbours) — never from another run of scenegrep.

Raw-data vocabulary used by every truth below (see the helpers):

* a vehicle is an object of a vehicle kind (car, truck, bus, trailer, motorcycle); its *lane* at a
  frame is the map lane containing its centre whose direction is nearest its heading
  (``RoadMap.lane_at`` with the heading: a lookup in the map's polygons, no labeller involved);
* its *speed* is the central finite difference of its recorded positions (so AV2 sensor logs,
  which record no velocities, have speeds too);
* *ahead* / *behind* of the ego: the other's centre minus the ego's, along the ego's heading;
* the *lanes ahead* of a lane are it and its successors up to 30 m past its end;
* a *lane change* to a side is a step (one frame) from lane A to lane B where B is A's neighbour
  on that side with traffic the same way (also through one successor or predecessor hop), outside
  intersections, with the vehicle's sideways motion across its lane's direction over the 2 s
  either side at least 1.2 m towards that side (so a box centre jittering on a boundary is none);
* the ego is the recording's ego; CommonRoad recordings have none (the planning problem's vehicle
  is not an object), so a program's ego may be any car there (README: "the program's ego is the
  trace's ego object when the trace names one"), and the truths take every car as the ego.

Per situation a test asserts positives and negatives (recording, object, frames) and the
confusion counts over all 20 recordings; the counts' unit is stated with each.
"""

from __future__ import annotations

import json
from collections import defaultdict
from functools import cache

import numpy as np
import pytest
import shapely

from scenegrep.model.geometry import heading_difference
from scenegrep.model.taxonomy import VEHICLE_KINDS, kind_of
from scenegrep.readers import read_map, read_trace
from tests.conftest import SHARED
from tests.library import catalog

pytestmark = pytest.mark.real_data

NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"
AV2_A = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
AV2_B = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"
WAYMO_SD = "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl"
WAYMO_A = "waymo_womd/motion_data_one_scenario.tfrecord"
US101_3 = "commonroad_ngsim/USA_US101-3_3_T-1.xml"
US101_4 = "commonroad_ngsim/USA_US101-4_1_T-1.xml"
LANKER = "commonroad_ngsim/USA_Lanker-1_1_T-1.xml"
REACH_M = 30.0
HALF_S = 2.0
MIN_SIDEWAYS_M = 1.2


# ---------------------------------------------------------------- raw data
class Raw:
    """One recording as dense (frames, objects) arrays of its raw states, with each state's lane."""

    def __init__(self, relative: str):
        trace = read_trace(SHARED / "real_data" / relative)
        self.map = read_map(trace.map_source)
        self.ids = [str(i) for i in trace.objects.id]
        self.kinds = [kind_of(str(c)) for c in trace.objects.category]
        self.ego = trace.ego
        self.t = np.asarray(trace.frame_time, dtype=float)
        self.x, self.y, self.h = trace.dense("x"), trace.dense("y"), trace.dense("heading")
        self.present = trace.present()
        s = trace.states
        lane_rows = self.map.lane_at(s.x, s.y, s.heading)
        self.lane = np.full(self.x.shape, -1, dtype=np.intp)
        self.lane[s.frame, s.object] = lane_rows
        self.lane_dir = np.full(self.x.shape, np.nan)
        self.lane_dir[s.frame, s.object] = self.map.lane_direction_at(s.x, s.y, lane_rows)
        self.inter = np.zeros(self.x.shape, dtype=bool)
        self.inter[s.frame, s.object] = self.map.in_intersection(s.x, s.y)
        self.speed = self._speeds()
        self.n_frames = len(self.t)
        self.vehicles = [k for k, kind in enumerate(self.kinds) if kind in VEHICLE_KINDS]
        self.egos = (
            [self.ids.index(self.ego)] if self.ego is not None else [k for k in self.vehicles if self.kinds[k] == "car"]
        )
        self._reach: dict[int, frozenset[int]] = {}

    def _speeds(self) -> np.ndarray:
        """Central (one-sided at track ends) finite differences of the positions, m/s; NaN unobserved."""
        x, y, p = self.x, self.y, self.present
        t = np.repeat(self.t[:, None], x.shape[1], axis=1)
        later = np.vstack([p[1:], np.zeros_like(p[:1])])
        earlier = np.vstack([np.zeros_like(p[:1]), p[:-1]])

        def shifted(a: np.ndarray, by: int, keep: np.ndarray) -> np.ndarray:
            moved = np.vstack([a[1:], a[-1:]]) if by > 0 else np.vstack([a[:1], a[:-1]])
            return np.where(keep, moved, a)

        dx = shifted(x, 1, later) - shifted(x, -1, earlier)
        dy = shifted(y, 1, later) - shifted(y, -1, earlier)
        dt = shifted(t, 1, later) - shifted(t, -1, earlier)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(p & (dt > 0), np.hypot(dx, dy) / dt, np.nan)

    def reach(self, lane: int) -> frozenset[int]:
        """The lane and its successors up to 30 m past its end (lane indices)."""
        if lane not in self._reach:
            index = self.map.lane_index
            found, todo = {lane}, [(lane, 0.0)]
            while todo:
                current, travelled = todo.pop()
                for successor in self.map.lanes[current].successors:
                    k = index.get(successor)
                    if k is None or k in found or travelled >= REACH_M:
                        continue
                    found.add(k)
                    todo.append((k, travelled + shapely.LineString(self.map.lanes[k].centreline).length))
            self._reach[lane] = frozenset(found)
        return self._reach[lane]

    def side_neighbours(self, lane: int, side: str) -> set[str]:
        """Ids of the same-direction lanes on ``side`` of a lane, also through one successor or
        predecessor hop of it."""
        index = self.map.lane_index
        own = self.map.lanes[lane]
        out = set()
        for lane_id in (own.id, *own.successors, *own.predecessors):
            if lane_id in index:
                neighbour = getattr(self.map.lanes[index[lane_id]], side)
                if neighbour is not None and neighbour.same_direction:
                    out.add(neighbour.lane)
        return out

    def beside(self, a: int, b: int, side: str) -> bool:
        """Whether lane b is a same-direction neighbour of lane a on ``side``."""
        other = {"left": "right", "right": "left"}[side]
        return self.map.lanes[b].id in self.side_neighbours(a, side) or self.map.lanes[a].id in self.side_neighbours(
            b, other
        )

    def along(self, f: int, ref: int, other: np.ndarray) -> np.ndarray:
        """How far the objects ``other`` are ahead of object ``ref`` along ref's heading at frame f (m)."""
        h = self.h[f, ref]
        return -np.sin(h) * (self.x[f, other] - self.x[f, ref]) + np.cos(h) * (self.y[f, other] - self.y[f, ref])

    def in_lane_ahead(self, f: int, ego: int) -> dict[int, float]:
        """Vehicles in the ego's lanes ahead at frame f, 0-30 m ahead of it: vehicle -> metres ahead."""
        if not self.present[f, ego] or self.lane[f, ego] < 0:
            return {}
        lanes = self.reach(int(self.lane[f, ego]))
        others = np.array([k for k in self.vehicles if k != ego and self.present[f, k] and self.lane[f, k] in lanes])
        if not len(others):
            return {}
        ahead = self.along(f, ego, others)
        return {int(k): float(a) for k, a in zip(others, ahead) if 0 < a <= REACH_M}


@cache
def raw(relative: str) -> Raw:
    return Raw(relative)


def lane_changes(relative: str) -> list[tuple[str, str, int, float]]:
    """(vehicle id, side, frame of the lane step, sideways metres over the 2 s either side)."""
    r = raw(relative)
    half = int(round(HALF_S / np.median(np.diff(r.t))))
    found = []
    for k in r.vehicles:
        frames = np.flatnonzero(r.present[:, k])
        if len(frames) < 2:
            continue
        x, y, d = r.x[frames, k], r.y[frames, k], r.lane_dir[frames, k]
        step = (np.diff(x) * -np.cos(d[:-1]) + np.diff(y) * -np.sin(d[:-1])) * (np.diff(frames) == 1)
        sideways = np.concatenate([[0.0], np.cumsum(np.nan_to_num(step))])  # to the left, m
        lanes, inter = r.lane[frames, k], r.inter[frames, k]
        for j in range(1, len(frames)):
            a, b = int(lanes[j - 1]), int(lanes[j])
            if a < 0 or b < 0 or a == b or frames[j] - frames[j - 1] != 1 or inter[j] or inter[j - 1]:
                continue
            moved = sideways[min(j + half, len(frames) - 1)] - sideways[max(j - half, 0)]
            for side, sign in (("left", 1.0), ("right", -1.0)):
                if r.beside(a, b, side) and sign * moved >= MIN_SIDEWAYS_M:
                    found.append((r.ids[k], side, int(frames[j]), round(float(sign * moved), 2)))
    return found


# ---------------------------------------------------------------- query answers
def answers(name: str, relative: str) -> dict[str, dict[str, list[tuple[int, int]]]]:
    """Program object -> label object -> its matching (first, last) frames, over the query's rows."""
    out: dict[str, dict[str, list[tuple[int, int]]]] = defaultdict(lambda: defaultdict(list))
    for row in catalog.matches(name, relative):
        for program_object, label_object in json.loads(row["correspondence"]).items():
            out[program_object][label_object].append((row["start_frame"], row["end_frame"]))
    return out


def matched_frames(name: str, relative: str) -> set[int]:
    return {f for row in catalog.matches(name, relative) for f in range(row["start_frame"], row["end_frame"] + 1)}


def confusion(truth: set, predicted: set, universe: set) -> tuple[int, int, int, int]:
    """(TP, FP, FN, TN) of a prediction against a truth over a universe of units."""
    assert truth <= universe and predicted <= universe, (truth - universe, predicted - universe)
    return (
        len(truth & predicted),
        len(predicted - truth),
        len(truth - predicted),
        len(universe - truth - predicted),
    )


def window_frames(relative: str, seconds: float) -> int:
    """A window of ``seconds`` in frames, as ``--window 3s`` rounds it (median frame period)."""
    return int(round(seconds / float(np.median(np.diff(raw(relative).t)))))


# ---------------------------------------------------------------- truths
def changing_lanes(side: str) -> set[tuple[str, str]]:
    """(recording, vehicle) with a lane change to ``side``."""
    return {(rel, vid) for rel in catalog.RECORDINGS for vid, s, _, _ in lane_changes(rel) if s == side}


def speed_gain(relative: str, vehicle: str, frame: int, half: int = 10) -> float:
    """Speed (m/s, from positions) ``half`` frames after ``frame`` minus ``half`` frames before it
    (clipped to the track)."""
    r = raw(relative)
    k = r.ids.index(vehicle)
    frames = np.flatnonzero(r.present[:, k])
    later = frames[frames <= frame + half].max()
    earlier = frames[frames >= frame - half].min()
    return float(r.speed[later, k] - r.speed[earlier, k])


def accelerating_right_changes() -> dict[tuple[str, str], float]:
    """(recording, vehicle) -> speed gain over the 2 s around a right lane change, for the changes
    that gain at least 1.3 m/s: RefAV's 0.65 m/s^2 sustained over the 2 s."""
    out = {}
    for rel in catalog.RECORDINGS:
        for vid, side, frame, _ in lane_changes(rel):
            gain = speed_gain(rel, vid, frame)
            if side == "right" and gain >= 1.3:
                out[(rel, vid)] = max(gain, out.get((rel, vid), gain))
    return out


def lane_ahead_frames(relative: str) -> dict[int, dict[tuple[int, int], float]]:
    """Per frame: (ego, vehicle) -> metres ahead, for vehicles in the ego's lanes 0-30 m ahead."""
    r = raw(relative)
    out = {}
    for f in range(r.n_frames):
        found = {(e, k): a for e in r.egos for k, a in r.in_lane_ahead(f, e).items()}
        if found:
            out[f] = found
    return out


def two_ahead_frames(relative: str) -> set[int]:
    """Frames where some vehicle is in the ego's lanes 0-30 m ahead and another in that vehicle's
    lanes 0-30 m ahead of it."""
    r = raw(relative)
    out = set()
    for f, pairs in lane_ahead_frames(relative).items():
        if any(r.in_lane_ahead(f, first) for _, first in pairs):
            out.add(f)
    return out


def runs(flags: np.ndarray, length: int) -> list[int]:
    """Starts of the windows of ``length`` frames in which every flag is set."""
    c = np.concatenate([[0], np.cumsum(flags.astype(int))])
    return [int(s) for s in range(len(flags) - length + 1) if c[s + length] - c[s] == length]


def following(relative: str, seconds: float = 3.0) -> dict[tuple[int, int], list[int]]:
    """(ego, lead) -> window starts in which, at every frame, the lead is in the ego's lanes 0-30 m
    ahead and both move faster than 1 m/s."""
    r = raw(relative)
    window = window_frames(relative, seconds)
    flags: dict[tuple[int, int], np.ndarray] = defaultdict(lambda: np.zeros(r.n_frames, dtype=bool))
    for f, pairs in lane_ahead_frames(relative).items():
        for e, k in pairs:
            flags[(e, k)][f] = r.speed[f, e] > 1 and r.speed[f, k] > 1
    out = {pair: runs(flag, window) for pair, flag in flags.items()}
    return {pair: starts for pair, starts in out.items() if starts}


def passes(relative: str, ref: int, other: int, sides: tuple[str, ...], window: int, moving: bool) -> list[int]:
    """Frames f1 where ``other`` is behind ``ref`` (along ref's heading) and, within ``window``
    frames of f1, ahead of it, in a same-direction lane beside ref's on one of ``sides`` at every
    frame from f1 to then (and ref moving faster than 1 m/s when ``moving``)."""
    r = raw(relative)
    both = r.present[:, ref] & r.present[:, other] & (r.lane[:, ref] >= 0) & (r.lane[:, other] >= 0)
    beside = np.zeros(r.n_frames, dtype=bool)
    ahead = np.full(r.n_frames, np.nan)
    for f in np.flatnonzero(both):
        a, b = int(r.lane[f, ref]), int(r.lane[f, other])
        beside[f] = any(r.beside(a, b, side) for side in sides) and (r.speed[f, ref] > 1 or not moving)
        ahead[f] = r.along(f, ref, np.array([other]))[0]
    starts = []
    for f1 in np.flatnonzero(beside & (ahead < 0)):
        for f2 in range(f1 + 1, min(f1 + window, r.n_frames)):
            if not beside[f2]:
                break
            if ahead[f2] > 0:
                starts.append(int(f1))
                break
    return starts


def overtaking(relative: str, seconds: float = 4.0) -> dict[tuple[int, int], list[int]]:
    """(ego, vehicle) -> frames where the vehicle, in a lane beside the moving ego's, is behind it
    and is ahead of it within ``seconds``, beside it all the while."""
    r = raw(relative)
    window = window_frames(relative, seconds)
    out = {}
    for e in r.egos:
        for k in r.vehicles:
            if k != e:
                starts = passes(relative, e, k, ("left", "right"), window, moving=True)
                if starts:
                    out[(e, k)] = starts
    return out


def overtaken_on_right_while_followed(relative: str, seconds: float = 4.0) -> dict[tuple[int, int, int], list[int]]:
    """(ego, lead, passer) -> frames where the ego follows the lead (as :func:`following`, frame by
    frame) while the passer, in the lane to the lead's right, is behind the lead and ahead of it
    within ``seconds``."""
    r = raw(relative)
    window = window_frames(relative, seconds)
    followed: dict[tuple[int, int], np.ndarray] = defaultdict(lambda: np.zeros(r.n_frames, dtype=bool))
    for f, pairs in lane_ahead_frames(relative).items():
        for e, k in pairs:
            followed[(e, k)][f] = r.speed[f, e] > 1 and r.speed[f, k] > 1
    out = {}
    for (e, lead), flags in followed.items():
        for k in r.vehicles:
            if k in (e, lead):
                continue
            starts = [s for s in passes(relative, lead, k, ("right",), window, moving=False) if flags[s]]
            if starts:
                out[(e, lead, k)] = starts
    return out
