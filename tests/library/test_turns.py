"""The turning and intersection situations of the real-situation library (issue 16): vehicles and
the ego turning left or right (at intersections), the ego turning left behind a lead vehicle, the
ego waiting at an intersection, moving vehicles near intersections and reversing vehicles.

Every expected answer is computed here from the recordings' raw numbers with numpy and shapely:
positions, headings and times as the readers give them (``scenegrep.readers.read_trace``) and the
map's intersection polygons (``scenegrep.readers.read_map``; nuScenes' are its lane connectors).
Speeds and velocities are central differences of positions over time (``np.gradient``) along each
track's runs of consecutive frames, for every dataset alike. Headings are Scenic's: 0 along +y,
counter-clockwise positive (a left turn makes the heading grow), so an object with heading h faces
(-sin h, cos h).

The truths, in the words a person would use (none is the labeller's rule):

* a **left (right) turn** is a span of at most 4 s (40 frames) over which the object's unwrapped
  heading grows (shrinks) by at least 0.6 rad (34 degrees) while it travels at least 3 m;
* **at an intersection**: the object's centre is inside the map's intersection region at some
  frame of the turn;
* **following**: at every frame of 2 s of the ego's left turn, the same vehicle moving faster than
  1 m/s is within 30 m of the ego, within 45 degrees of the ego's heading as seen from the ego, and
  faces within 60 degrees of the ego's heading;
* **waiting at an intersection**: the ego moves slower than 0.5 m/s at every frame of 2 s with its
  centre within 10 m of the intersection region;
* **near an intersection** (per frame): a vehicle other than the ego moving faster than 1 m/s has
  its centre within 5 m of (or inside) the intersection region;
* **reversing**: the speed along the vehicle's own heading is below -0.3 m/s at every frame of 2 s.

The program's ego is the recording's ego; CommonRoad scenarios record none, and there (as
scenegrep does) any car may play the ego, so the truth ranges over every car as the ego. "Vehicle"
is the canonical kinds car, truck, bus, trailer and motorcycle (Scenic's ``Vehicle``). Counts are
per recording (``ego_*``), per (recording, object) for the vehicle situations, and per (recording,
frame) for ``vehicle_near_intersection``; each disagreement is named with its reason.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest
import shapely

from scenegrep.model.taxonomy import VEHICLE_KINDS, kind_of
from scenegrep.readers import read_map, read_trace
from tests.conftest import SHARED
from tests.library import catalog

pytestmark = pytest.mark.real_data

NAMES = (
    "vehicle_turning_left_at_intersection",
    "vehicle_turning_right",
    "ego_turning_left_following_vehicle",
    "ego_waiting_at_intersection",
    "vehicle_near_intersection",
    "vehicle_reversing",
    "ego_turning_right_at_intersection",
)
ROLE = {
    "vehicle_turning_left_at_intersection": "car",
    "vehicle_turning_right": "vehicle",
    "vehicle_reversing": "vehicle",
    "vehicle_near_intersection": "vehicle",
}
"""The program object whose label objects the object-level answers are about (else the ego)."""

NUSC = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{}.pkl"
AV2_STOP = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"
AV2_START = "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76"
WAYMO_ONE = "waymo_womd/motion_data_one_scenario.tfrecord"
WAYMO_INPUT = "waymo_womd/womd_scenario_input.tfrecord"
WAYMO_SD = "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl"
PEACH = "commonroad_ngsim/USA_Peach-4_8_T-1.xml"
LANKER = "commonroad_ngsim/USA_Lanker-1_1_T-1.xml"
US101 = "commonroad_ngsim/USA_US101-3_3_T-1.xml"

WINDOW = 20
"""The queries' 2 s windows, in frames (every recording is 10 Hz)."""
TURN_RAD, TURN_FRAMES, TURN_TRAVEL_M = 0.6, 40, 3.0
LEAD_RANGE_M, LEAD_BEARING_RAD, LEAD_HEADING_RAD, LEAD_SPEED_MPS = 30.0, np.pi / 4, np.pi / 3, 1.0
WAIT_SPEED_MPS, WAIT_DISTANCE_M = 0.5, 10.0
NEAR_SPEED_MPS, NEAR_DISTANCE_M = 1.0, 5.0
REVERSE_MPS = -0.3


# ---------------------------------------------------------------- the raw numbers
@dataclass(frozen=True)
class Track:
    """One object's states in frame order: frames, times (s), centre x, y (m), heading (rad),
    velocity vx, vy (m/s, central differences within runs of consecutive frames)."""

    id: str
    kind: str
    frame: np.ndarray
    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    vx: np.ndarray
    vy: np.ndarray

    @property
    def speed(self) -> np.ndarray:
        return np.hypot(self.vx, self.vy)

    @property
    def along(self) -> np.ndarray:
        """The speed along the object's own heading (negative: moving backwards)."""
        return -np.sin(self.heading) * self.vx + np.cos(self.heading) * self.vy

    def at(self, values: np.ndarray) -> dict[int, float]:
        return dict(zip(self.frame.tolist(), np.asarray(values).tolist()))


def differences(t: np.ndarray, v: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """dv/dt by central differences within each run of consecutive frames (0 on a run of one)."""
    out = np.zeros(len(v))
    breaks = np.flatnonzero(np.diff(frame) != 1) + 1
    for run in np.split(np.arange(len(v)), breaks):
        if len(run) > 1:
            out[run] = np.gradient(v[run], t[run])
    return out


@cache
def recording(relative: str) -> tuple[str | None, int, dict[str, Track], object]:
    """The recording's ego id, frame count, tracks by id, and its intersection region (a shapely
    geometry, or None when the map has no intersection)."""
    trace = read_trace(SHARED / "real_data" / relative)
    s = trace.states
    tracks = {}
    for k, object_id in enumerate(trace.objects.id):
        rows = np.flatnonzero(s.object == k)
        rows = rows[np.argsort(s.frame[rows])]
        frame = s.frame[rows].astype(int)
        t = trace.frame_time[frame]
        x, y = s.x[rows], s.y[rows]
        kind = "ego" if str(object_id) == trace.ego else kind_of(str(trace.objects.category[k]))
        tracks[str(object_id)] = Track(
            str(object_id), kind, frame, t, x, y, s.heading[rows], differences(t, x, frame), differences(t, y, frame)
        )
    region = None
    if trace.map_source is not None:
        road_map = read_map(trace.map_source)
        if road_map.intersections:
            region = shapely.union_all([area.polygon for area in road_map.intersections])
    return trace.ego, len(trace.frame_time), tracks, region


def egos(relative: str) -> list[str]:
    """Who may play the program's ego: the recording's ego, else (CommonRoad) every car."""
    ego, _, tracks, _ = recording(relative)
    return [ego] if ego is not None else [i for i, tr in tracks.items() if tr.kind == "car"]


def vehicles(relative: str, kinds: frozenset[str] = VEHICLE_KINDS) -> list[str]:
    """The recording's objects of ``kinds`` other than its ego."""
    return [i for i, tr in recording(relative)[2].items() if tr.kind in kinds]


def inside(relative: str, track: Track) -> np.ndarray:
    """Per state, whether the centre is inside the intersection region."""
    region = recording(relative)[3]
    return np.zeros(len(track.x), bool) if region is None else shapely.contains_xy(region, track.x, track.y)


def distance_to_intersection(relative: str, track: Track) -> np.ndarray:
    region = recording(relative)[3]
    if region is None:
        return np.full(len(track.x), np.inf)
    return shapely.distance(region, shapely.points(track.x, track.y))


def turns(track: Track, sign: int) -> list[tuple[int, int]]:
    """The turns of a track to the left (sign 1) or right (-1): (first, last frame) of every span of
    at most TURN_FRAMES consecutive frames over which the heading changes by TURN_RAD that way
    while the object travels TURN_TRAVEL_M."""
    u = np.unwrap(track.heading)
    step = np.hypot(np.diff(track.x), np.diff(track.y))
    travelled = np.concatenate([[0.0], np.cumsum(step)])
    spans = []
    for k in range(1, min(TURN_FRAMES, len(u) - 1) + 1):
        ok = (
            (sign * (u[k:] - u[:-k]) >= TURN_RAD)
            & (track.frame[k:] - track.frame[:-k] == k)
            & (travelled[k:] - travelled[:-k] >= TURN_TRAVEL_M)
        )
        spans += [(int(track.frame[i]), int(track.frame[i + k])) for i in np.flatnonzero(ok)]
    return spans


def turn_frames(track: Track, sign: int) -> set[int]:
    return {f for first, last in turns(track, sign) for f in range(first, last + 1)}


def turns_at_intersection(relative: str, track: Track, sign: int) -> list[tuple[int, int]]:
    """The turns during which the centre is inside the intersection region at some frame."""
    entered = set(track.frame[inside(relative, track)].tolist())
    return [(a, b) for a, b in turns(track, sign) if any(f in entered for f in range(a, b + 1))]


def runs_of(frames: set[int], length: int) -> list[tuple[int, int]]:
    """The maximal runs of consecutive frames in ``frames`` at least ``length`` long."""
    out, ordered = [], sorted(frames)
    start = None
    for i, f in enumerate(ordered):
        if start is None:
            start = f
        if i + 1 == len(ordered) or ordered[i + 1] != f + 1:
            if f - start + 1 >= length:
                out.append((start, f))
            start = None
    return out


def lead_frames(relative: str, ego_id: str, lead_id: str) -> set[int]:
    """Frames at which ``lead_id`` drives ahead of ``ego_id`` the same way (see the module doc)."""
    tracks = recording(relative)[2]
    ego, lead = tracks[ego_id], tracks[lead_id]
    common, ie, il = np.intersect1d(ego.frame, lead.frame, return_indices=True)
    dx, dy = lead.x[il] - ego.x[ie], lead.y[il] - ego.y[ie]
    bearing = np.arctan2(-dx, dy)  # Scenic's heading of the direction from the ego to the lead
    off = np.angle(np.exp(1j * (bearing - ego.heading[ie])))
    facing = np.angle(np.exp(1j * (lead.heading[il] - ego.heading[ie])))
    ok = (
        (np.hypot(dx, dy) <= LEAD_RANGE_M)
        & (np.abs(off) <= LEAD_BEARING_RAD)
        & (np.abs(facing) < LEAD_HEADING_RAD)
        & (lead.speed[il] > LEAD_SPEED_MPS)
    )
    return set(common[ok].tolist())


# ---------------------------------------------------------------- the truths
@cache
def truth(name: str, relative: str) -> dict[str, list[tuple[int, int]]]:
    """The situation's raw-data truth on one recording: the object in the situation's role (the ego
    for ``ego_*``; the frame number as text for ``vehicle_near_intersection``) -> (first, last
    frame) spans where it holds."""
    ego, n_frames, tracks, region = recording(relative)
    out: dict[str, list[tuple[int, int]]] = {}
    if name == "vehicle_turning_left_at_intersection":
        for i in vehicles(relative, frozenset({"car"})):
            if spans := turns_at_intersection(relative, tracks[i], 1):
                out[i] = spans
    elif name == "vehicle_turning_right":
        for i in vehicles(relative):
            if spans := turns(tracks[i], -1):
                out[i] = spans
    elif name == "ego_turning_right_at_intersection":
        for e in egos(relative):
            if spans := turns_at_intersection(relative, tracks[e], -1):
                out[e] = spans
    elif name == "ego_turning_left_following_vehicle":
        for e in egos(relative):
            turning = turn_frames(tracks[e], 1)
            if not turning:
                continue
            for lead in vehicles(relative):
                if lead != e and (spans := runs_of(turning & lead_frames(relative, e, lead), WINDOW)):
                    out.setdefault(e, []).extend(spans)
    elif name == "ego_waiting_at_intersection":
        for e in egos(relative):
            tr = tracks[e]
            waiting = (tr.speed < WAIT_SPEED_MPS) & (distance_to_intersection(relative, tr) < WAIT_DISTANCE_M)
            if spans := runs_of(set(tr.frame[waiting].tolist()), WINDOW):
                out[e] = spans
    elif name == "vehicle_near_intersection":
        for i in vehicles(relative):
            tr = tracks[i]
            near = (tr.speed > NEAR_SPEED_MPS) & (distance_to_intersection(relative, tr) < NEAR_DISTANCE_M)
            for f in tr.frame[near].tolist():
                out.setdefault(str(f), []).append((f, f))
    elif name == "vehicle_reversing":
        for i in vehicles(relative):
            tr = tracks[i]
            if spans := runs_of(set(tr.frame[tr.along < REVERSE_MPS].tolist()), WINDOW):
                out[i] = spans
    return out


# ---------------------------------------------------------------- the queries' answers
@cache
def all_matches() -> dict[tuple[str, str], tuple[dict, ...]]:
    """Every query's match rows on every recording, recording by recording (the readers keep a
    recording's map cached while every query runs over it)."""
    return {
        (name, relative): tuple(catalog.matches(name, relative)) for relative in catalog.RECORDINGS for name in NAMES
    }


def found(name: str, relative: str) -> dict[str, list[tuple[int, int]]]:
    """The query's answers, keyed as :func:`truth` keys them, -> its matching windows."""
    role = ROLE.get(name, "ego")
    out: dict[str, list[tuple[int, int]]] = {}
    for row in all_matches()[name, relative]:
        window = (int(row["start_frame"]), int(row["end_frame"]))
        key = str(window[0]) if name == "vehicle_near_intersection" else json.loads(row["correspondence"])[role]
        out.setdefault(key, []).append(window)
    return out


def overlaps(a: list[tuple[int, int]], b: list[tuple[int, int]]) -> bool:
    return any(x0 <= y1 and y0 <= x1 for x0, x1 in a for y0, y1 in b)


def universe(name: str, relative: str) -> list[str]:
    """What the counts range over on one recording: the recording itself (``ego_*``: one unit,
    keyed '*'), its frames, or its objects in the situation's role."""
    if name.startswith("ego_"):
        return ["*"]
    if name == "vehicle_near_intersection":
        return [str(f) for f in range(recording(relative)[1])]
    kinds = frozenset({"car"}) if name == "vehicle_turning_left_at_intersection" else VEHICLE_KINDS
    return vehicles(relative, kinds)


def confusion(name: str) -> dict[str, list[tuple[str, str]]]:
    """TP/FP/FN/TN units of one situation over the 20 recordings."""
    out: dict[str, list[tuple[str, str]]] = {"TP": [], "FP": [], "FN": [], "TN": []}
    for relative in catalog.RECORDINGS:
        true, answer = truth(name, relative), found(name, relative)
        if name.startswith("ego_"):
            true, answer = ({"*": []} if true else {}), ({"*": []} if answer else {})
        for unit in universe(name, relative):
            cell = ("T" if (unit in true) == (unit in answer) else "F") + ("P" if unit in answer else "N")
            out[cell].append((relative, unit))
    return out
