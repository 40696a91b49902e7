"""The motion situations of the real-situation library (issue 16): standing still, speed, braking,
starting, facing / heading toward the ego, oncoming and crossing vehicles.

Every expected answer is computed here from the recordings' raw numbers with numpy: positions,
headings and times as the readers give them (``scenegrep.readers.read_trace``). Speeds and
velocities are central differences of positions over time (``np.gradient``) along each track's
runs of consecutive frames, for every dataset alike, never the velocity columns a dataset
records (nuScenes' recorded velocity is 0 or off by up to 14 m/s at some scenes' last frames, where
the positions keep moving). Headings are Scenic's: 0 along +y, counter-clockwise positive, so an
object with heading h faces (-sin h, cos h).

The program's ego is the recording's ego; CommonRoad scenarios record none, and there (as
scenegrep does) any car may play the ego, so the truth there ranges over every car as the ego.
"Vehicle" is the canonical kinds car, truck, bus, trailer and motorcycle (Scenic's ``Vehicle``).

Each situation's truth is a window of the query's length (frames at 10 Hz) in which the situation
holds at every frame (or, for the temporal parts, at the first / some frame), on frames where the
objects are all observed. Counts are per recording (``ego_*`` situations) or per (recording,
vehicle) with the vehicle in the situation's other role; the tests assert the counts and each
disagreement is named with its reason.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest

from scenegrep.model.taxonomy import VEHICLE_KINDS, kind_of
from scenegrep.readers import read_trace
from tests.conftest import SHARED
from tests.library import catalog

pytestmark = pytest.mark.real_data

NAMES = (
    "stationary_vehicle",
    "ego_high_speed",
    "lead_vehicle_braking",
    "ego_accelerating_from_stop",
    "vehicle_facing_toward_ego",
    "vehicle_heading_toward_ego",
    "oncoming_vehicle",
    "vehicle_crossing_ego_path",
)
ROLE = {
    "stationary_vehicle": "parked",
    "lead_vehicle_braking": "lead",
    "vehicle_facing_toward_ego": "other",
    "vehicle_heading_toward_ego": "other",
    "oncoming_vehicle": "other",
    "vehicle_crossing_ego_path": "other",
}
"""The program object whose label objects the object-level counts are about."""

NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"
AV2_STOP = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
AV2_START = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"


@cache
def all_matches() -> dict[tuple[str, str], tuple[dict, ...]]:
    """Every query's match rows on every recording, recording by recording (the readers keep a
    recording's map cached while every query runs over it)."""
    return {
        (name, recording): tuple(catalog.matches(name, recording))
        for recording in catalog.RECORDINGS
        for name in NAMES
    }


def found(name: str, recording: str) -> dict[str, list[tuple[int, int]]]:
    """The query's answers: the label object in the situation's role (the ego for ``ego_*``) ->
    its matching windows (first, last frame)."""
    role = ROLE.get(name, "ego")
    out: dict[str, list[tuple[int, int]]] = {}
    for row in all_matches()[name, recording]:
        out.setdefault(json.loads(row["correspondence"])[role], []).append((row["start_frame"], row["end_frame"]))
    return out


# ---------------------------------------------------------------- raw numbers
@dataclass(frozen=True)
class Raw:
    """One recording as dense (object, frame) arrays: NaN where the object is not observed."""

    ids: tuple[str, ...]
    kinds: tuple[str, ...]
    egos: tuple[int, ...]
    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    vx: np.ndarray
    vy: np.ndarray

    @property
    def speed(self) -> np.ndarray:
        return np.hypot(self.vx, self.vy)

    @property
    def present(self) -> np.ndarray:
        return ~np.isnan(self.x)

    def index(self, object_id: str) -> int:
        return self.ids.index(object_id)

    def vehicles(self) -> list[int]:
        return [k for k, kind in enumerate(self.kinds) if kind in VEHICLE_KINDS]


@cache
def raw(recording: str) -> Raw:
    trace = read_trace(SHARED / "real_data" / recording)
    s = trace.states
    n, frames = len(trace.objects.id), len(trace.frame_index)
    arrays = {name: np.full((n, frames), np.nan) for name in ("x", "y", "heading", "vx", "vy")}
    for k in range(n):
        rows = np.flatnonzero(s.object == k)
        rows = rows[np.argsort(s.frame[rows])]
        f = s.frame[rows].astype(int)
        t = trace.frame_time[f]
        for name in ("x", "y", "heading"):
            arrays[name][k, f] = getattr(s, name)[rows]
        # velocities: central differences within each run of consecutive frames
        for run in np.split(np.arange(len(f)), np.flatnonzero(np.diff(f) != 1) + 1):
            if len(run) >= 2:
                arrays["vx"][k, f[run]] = np.gradient(s.x[rows][run], t[run])
                arrays["vy"][k, f[run]] = np.gradient(s.y[rows][run], t[run])
    kinds = tuple(kind_of(str(c)) for c in trace.objects.category)
    ids = tuple(str(i) for i in trace.objects.id)
    egos = (ids.index(trace.ego),) if trace.ego is not None else tuple(k for k, kind in enumerate(kinds) if kind == "car")
    return Raw(ids, kinds, egos, **arrays)


def windows_all(flags: np.ndarray, m: int) -> np.ndarray:
    """Per window start (along the last axis), whether ``flags`` holds at all m frames."""
    c = np.concatenate([np.zeros(flags.shape[:-1] + (1,)), np.cumsum(flags, axis=-1)], axis=-1)
    return (c[..., m:] - c[..., :-m]) == m


def windows_any(flags: np.ndarray, m: int) -> np.ndarray:
    c = np.concatenate([np.zeros(flags.shape[:-1] + (1,)), np.cumsum(flags, axis=-1)], axis=-1)
    return (c[..., m:] - c[..., :-m]) > 0


def wrap(angle: np.ndarray) -> np.ndarray:
    return (angle + np.pi) % (2 * np.pi) - np.pi


@dataclass(frozen=True)
class Pair:
    """Per frame, another object seen from an ego: offsets along and to the left of the ego's
    heading (m), distance (m), heading difference (rad), and the other's own kinematics."""

    ahead: np.ndarray
    left: np.ndarray
    distance: np.ndarray
    relative_heading: np.ndarray
    facing: np.ndarray  # angle between the other's heading and its direction to the ego
    velocity_to_ego: np.ndarray  # angle between the other's velocity and its direction to the ego
    closing: np.ndarray  # the distance's rate of change (m/s), central differences
    speed: np.ndarray
    ego_speed: np.ndarray
    both: np.ndarray


def pair(r: Raw, ego: int, other: int) -> Pair:
    dx, dy = r.x[other] - r.x[ego], r.y[other] - r.y[ego]
    h = r.heading[ego]
    ahead = -np.sin(h) * dx + np.cos(h) * dy
    left = -np.cos(h) * dx - np.sin(h) * dy
    distance = np.hypot(dx, dy)
    to_ego = np.arctan2(dx, -dy)  # Scenic heading of the vector (-dx, -dy), from the other to the ego
    velocity_heading = np.arctan2(-r.vx[other], r.vy[other])
    both = r.present[ego] & r.present[other]
    closing = np.full_like(distance, np.nan)
    closing[1:-1] = (distance[2:] - distance[:-2]) / 0.2
    return Pair(
        ahead,
        left,
        distance,
        wrap(r.heading[other] - h),
        np.abs(wrap(r.heading[other] - to_ego)),
        np.abs(wrap(velocity_heading - to_ego)),
        closing,
        r.speed[other],
        r.speed[ego],
        both,
    )


def truth_windows(name: str, recording: str) -> dict[str, np.ndarray]:
    """The raw-data truth: the label object in the situation's role -> the starts of the windows
    in which the situation holds (with some ego, for the object situations)."""
    r = raw(recording)
    m = WINDOW[name]
    out: dict[str, np.ndarray] = {}
    if r.x.shape[1] < m:
        return out
    if name.startswith("ego_"):
        for ego in r.egos:
            v = r.speed[ego]
            seen = windows_all(~np.isnan(v), m)
            if name == "ego_high_speed":
                starts = seen & windows_all(v > 13.9, m)
            else:  # standing at the window's first frame, over 3 m/s at a later one
                starts = seen & (v[: len(v) - m + 1] < 0.5) & windows_any(v > 3, m)
            if starts.any():
                out[r.ids[ego]] = np.flatnonzero(starts)
        return out
    for other in r.vehicles():
        starts = np.zeros(r.x.shape[1] - WINDOW[name] + 1, bool)
        for ego in r.egos:
            if ego != other:
                starts |= pair_truth(name, r, ego, other)
        if starts.any():
            out[r.ids[other]] = np.flatnonzero(starts)
    return out


WINDOW = {
    "stationary_vehicle": 50,
    "ego_high_speed": 30,
    "lead_vehicle_braking": 10,
    "ego_accelerating_from_stop": 50,
    "vehicle_facing_toward_ego": 10,
    "vehicle_heading_toward_ego": 10,
    "oncoming_vehicle": 30,
    "vehicle_crossing_ego_path": 30,
}
"""The queries' windows in frames (all recordings are 10 Hz)."""


def pair_truth(name: str, r: Raw, ego: int, other: int) -> np.ndarray:
    m = WINDOW[name]
    p = pair(r, ego, other)
    with np.errstate(invalid="ignore"):
        if name == "stationary_vehicle":
            # within 0.5 m of where it stands at the window's start, at every frame of it
            x, y = r.x[other], r.y[other]
            n = len(x) - m + 1
            shift = np.array([np.nanmax(np.hypot(x[s : s + m] - x[s], y[s : s + m] - y[s])) if p.both[s] else np.inf for s in range(n)])
            return windows_all(p.both, m) & (shift <= 0.5)
        if name == "lead_vehicle_braking":
            ahead = (p.ahead > 2) & (p.ahead < 40) & (np.abs(p.left) < 2) & (np.abs(p.relative_heading) < np.radians(30))
            v = p.speed
            n = len(v) - m + 1
            drop = np.full(n, np.nan)
            drop[:] = (v[: n] - v[m - 1 :]) / ((m - 1) * 0.1)  # mean deceleration over the window
            return windows_all(p.both & ahead & (p.ego_speed > 0.5), m) & (drop > 1.0)
        if name == "vehicle_facing_toward_ego":
            return windows_all(p.both & (p.facing < np.radians(30)) & (p.distance < 30), m)
        if name == "vehicle_heading_toward_ego":
            cond = (p.speed > 1) & (p.distance < 30) & (p.velocity_to_ego < np.radians(30)) & (p.closing < 0)
            return windows_all(p.both & cond, m)
        if name == "oncoming_vehicle":
            cond = (p.speed > 1) & (np.abs(p.relative_heading) > np.radians(150)) & (np.abs(p.left) < 20)
            n = len(p.ahead) - m + 1
            return windows_all(p.both & cond, m) & (p.ahead[:n] > 0) & windows_any(p.ahead <= 0, m)
        if name == "vehicle_crossing_ego_path":
            turn = np.abs(p.relative_heading)
            cond = (p.speed > 1) & (turn > np.radians(60)) & (turn < np.radians(120)) & (p.ahead > 0) & (p.ahead < 30)
            return windows_all(p.both & cond, m) & windows_any(p.left > 0, m) & windows_any(p.left < 0, m)
    raise KeyError(name)
