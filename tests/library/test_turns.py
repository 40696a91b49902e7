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
* **near an intersection** (per vehicle and frame): a vehicle other than the ego moving faster
  than 1 m/s has its centre within 5 m of (or inside) the intersection region;
* **reversing**: the speed along the vehicle's own heading is below -0.3 m/s at every frame of 2 s.

The program's ego is the recording's ego; CommonRoad scenarios record none, and there (as
scenegrep does) any car may play the ego, so the truth ranges over every car as the ego. "Vehicle"
is the canonical kinds car, truck, bus, trailer and motorcycle (Scenic's ``Vehicle``). Counts are
per recording (``ego_*``), per (recording, object) for the vehicle situations, and per (recording,
vehicle, frame) for ``vehicle_near_intersection``; each disagreement is checked for its reason.
"""

from __future__ import annotations

import json
from collections import Counter
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
    recorded_speed: np.ndarray
    """The speed the recording itself gives (its velocity columns; AV2 sensor logs: the reader's
    estimates from positions), which the queries read: used only to explain disagreements."""

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
            str(object_id),
            kind,
            frame,
            t,
            x,
            y,
            s.heading[rows],
            differences(t, x, frame),
            differences(t, y, frame),
            np.hypot(s.vx[rows], s.vy[rows]),
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
    """The turns of a track to the left (sign 1) or right (-1): the (first, last frame) runs of the
    frames covered by spans of at most TURN_FRAMES consecutive frames over which the heading
    changes by TURN_RAD that way while the object travels TURN_TRAVEL_M."""
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
    return runs_of({f for first, last in spans for f in range(first, last + 1)}, 1)


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
    for ``ego_*``; 'object@frame' for ``vehicle_near_intersection``) -> (first, last frame) spans
    where it holds."""
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
                out[f"{i}@{f}"] = [(f, f)]
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
        key = json.loads(row["correspondence"])[role]
        if name == "vehicle_near_intersection":
            key, window = f"{key}@{window[0]}", (window[0], window[0])
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
        return [f"{i}@{f}" for i in vehicles(relative) for f in recording(relative)[2][i].frame.tolist()]
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


def largest_turn(track: Track, sign: int, first: int = 0, last: int = 10**9) -> float:
    """The largest heading change (rad) to the left (sign 1) or right (-1) over at most TURN_FRAMES
    consecutive frames between ``first`` and ``last``, travelling TURN_TRAVEL_M (0 if none)."""
    u = np.unwrap(track.heading)
    travelled = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(track.x), np.diff(track.y)))])
    best = 0.0
    for k in range(1, min(TURN_FRAMES, len(u) - 1) + 1):
        ok = (
            (track.frame[k:] - track.frame[:-k] == k)
            & (travelled[k:] - travelled[:-k] >= TURN_TRAVEL_M)
            & (track.frame[:-k] >= first)
            & (track.frame[k:] <= last)
        )
        if ok.any():
            best = max(best, float((sign * (u[k:] - u[:-k]))[ok].max()))
    return best


def track(relative: str, prefix: str) -> Track:
    """The track whose id starts with ``prefix``."""
    (found_track,) = [tr for i, tr in recording(relative)[2].items() if i.startswith(prefix)]
    return found_track


def answer(name: str, relative: str, object_id: str) -> list[tuple[int, int]]:
    """The query's windows for one label object."""
    return found(name, relative).get(object_id, [])


def check_positive(name: str, relative: str, prefix: str, frames: tuple[int, int]) -> None:
    """The truth holds for the object around ``frames`` and the query answers it there."""
    key = track(relative, prefix).id if prefix != "*" else "*"
    true = truth(name, relative)
    spans = [s for k, v in true.items() if k == key or prefix == "*" for s in v]
    assert overlaps(spans, [frames]), (name, relative, prefix, spans)
    windows = answer(name, relative, key) if prefix != "*" else [w for v in found(name, relative).values() for w in v]
    assert overlaps(windows, [frames]), (name, relative, prefix, windows[:3])
    assert overlaps(windows, spans)


def check_negative(name: str, relative: str, prefix: str = "*") -> None:
    """Neither the truth nor the query has the object (``*``: anything on the recording)."""
    if prefix == "*":
        assert truth(name, relative) == {} and found(name, relative) == {}, (name, relative)
    else:
        key = track(relative, prefix).id
        assert key not in truth(name, relative) and key not in found(name, relative), (name, relative, prefix)


# ---------------------------------------------------------------- vehicle turning left at an intersection
def test_vehicle_turning_left_at_intersection_positives():
    """nuScenes scene-0061 car c1958768 turns left through the intersection (heading +1.19 rad in
    4 s); Waymo (motion_data_one_scenario) car 1675 +1.06 rad; CommonRoad Peach-4_8 (tag TURN_LEFT)
    car 605 +0.60 rad, each with its centre inside the intersection during the turn."""
    name = "vehicle_turning_left_at_intersection"
    assert largest_turn(track(NUSC.format("0061"), "c1958768"), 1) > 1.1
    check_positive(name, NUSC.format("0061"), "c1958768", (50, 69))
    assert largest_turn(track(WAYMO_ONE, "1675"), 1) > 1.0
    check_positive(name, WAYMO_ONE, "1675", (43, 62))
    assert largest_turn(track(PEACH, "605"), 1) >= TURN_RAD
    check_positive(name, PEACH, "605", (44, 58))


def test_vehicle_turning_left_at_intersection_negatives():
    """scene-0061 car bc38961c turns right (-1.13 rad), never left; AV2 7fab2350 car a409f36b turns
    right (-1.40 rad); the straight highway US101-3_3 has no turn at all (largest heading change of
    any vehicle either way in 4 s below 0.2 rad)."""
    name = "vehicle_turning_left_at_intersection"
    assert largest_turn(track(NUSC.format("0061"), "bc38961c"), -1) > 1.1
    assert largest_turn(track(NUSC.format("0061"), "bc38961c"), 1) < 0.1
    check_negative(name, NUSC.format("0061"), "bc38961c")
    assert largest_turn(track(AV2_STOP, "a409f36b"), -1) > 1.3
    check_negative(name, AV2_STOP, "a409f36b")
    assert max(largest_turn(tr, s) for tr in recording(US101)[2].values() for s in (1, -1)) < 0.2
    check_negative(name, US101)


# ---------------------------------------------------------------- vehicle turning right
def test_vehicle_turning_right_positives():
    """scene-0061 car bc38961c (-1.13 rad in 4 s) and truck a60047ad (-1.05 rad); AV2 7fab2350 car
    a409f36b (-1.40 rad, frames 115-155); CommonRoad Lanker-1_1 car 1253 (-1.06 rad)."""
    name = "vehicle_turning_right"
    assert largest_turn(track(NUSC.format("0061"), "bc38961c"), -1) > 1.1
    check_positive(name, NUSC.format("0061"), "bc38961c", (49, 68))
    assert track(NUSC.format("0061"), "a60047ad").kind == "truck"
    check_positive(name, NUSC.format("0061"), "a60047ad", (40, 80))
    assert largest_turn(track(AV2_STOP, "a409f36b"), -1, 100, 155) > 1.3
    check_positive(name, AV2_STOP, "a409f36b", (113, 132))
    assert largest_turn(track(LANKER, "1253"), -1) > 1.0
    check_positive(name, LANKER, "1253", (0, 20))


def test_vehicle_turning_right_negatives():
    """scene-0061 car c1958768 turns left only (largest right turn below 0.1 rad); AV2 7fab2350 car
    688118c3 only backs up (no 4 s heading change over 0.6 rad); US101-3_3 has no turn."""
    name = "vehicle_turning_right"
    assert largest_turn(track(NUSC.format("0061"), "c1958768"), -1) < 0.1
    check_negative(name, NUSC.format("0061"), "c1958768")
    assert largest_turn(track(AV2_STOP, "688118c3"), -1) < TURN_RAD
    check_negative(name, AV2_STOP, "688118c3")
    check_negative(name, US101)


# ---------------------------------------------------------------- ego turning left behind a vehicle
def test_ego_turning_left_following_vehicle_positives():
    """nuScenes scene-0061: the ego turns left (+0.84 rad in 4 s around frame 95) behind car
    c1958768, 13-18 m ahead at 3-4 m/s and turning left too (+1.19 rad); scene-1094: the ego turns
    left (+1.23 rad around frame 65) behind car 3f81e988, 10-17 m ahead at 3-7 m/s; scene-1077:
    the ego bears left (+0.81 rad around frame 20) behind car ed634e83, 16-22 m ahead at 8-10 m/s."""
    name = "ego_turning_left_following_vehicle"
    for scene, lead, frames in (
        ("0061", "c1958768", (62, 100)),
        ("1094", "3f81e988", (43, 80)),
        ("1077", "ed634e83", (0, 25)),
    ):
        relative = NUSC.format(scene)
        ego = track(relative, "ego")
        assert largest_turn(ego, 1) > 0.8
        lead_id = track(relative, lead).id
        following = runs_of(turn_frames(ego, 1) & lead_frames(relative, "ego", lead_id), WINDOW)
        assert overlaps(following, [frames]), (scene, following)
        check_positive(name, relative, "*", frames)
        assert any(json.loads(r["correspondence"])["lead"] == lead_id for r in all_matches()[name, relative])


def test_ego_turning_left_following_vehicle_negatives():
    """scene-0916: the ego turns left at the end (+1.15 rad around frame 180) with no moving vehicle
    ahead within 30 m; AV2 7fab2350: the ego turns left after its stop (+1.10 rad around frame 135),
    alone; scene-0553: the ego stands still for the whole scene."""
    name = "ego_turning_left_following_vehicle"
    for relative in (NUSC.format("0916"), AV2_STOP):
        assert largest_turn(track(relative, "ego"), 1) > 1.0
        check_negative(name, relative)
    assert track(NUSC.format("0553"), "ego").speed.max() < 0.1
    check_negative(name, NUSC.format("0553"))


# ---------------------------------------------------------------- ego waiting at an intersection
def test_ego_waiting_at_intersection_positives():
    """nuScenes scene-0553: the ego stands (below 0.1 m/s) the whole scene 3.9 m before the
    intersection; scene-0757: it stops at frame 83 beside it; AV2 7fab2350: it brakes to a stop
    (below 0.5 m/s over frames 96-115) at the intersection; Waymo motion_data_one_scenario: its ego
    2406 stands 3.6 m from an intersection for the whole 9 s."""
    name = "ego_waiting_at_intersection"
    check_positive(name, NUSC.format("0553"), "*", (0, 200))
    check_positive(name, NUSC.format("0757"), "*", (83, 200))
    check_positive(name, AV2_STOP, "*", (96, 115))
    check_positive(name, WAYMO_ONE, "*", (0, 90))
    ego = track(NUSC.format("0553"), "ego")
    assert ego.speed.max() < 0.1 and 3.5 < distance_to_intersection(NUSC.format("0553"), ego).min() < 4


def test_ego_waiting_at_intersection_negatives():
    """nuScenes scene-0061: the ego never stands (slowest 0.7 m/s); AV2 adcf7d18: the ego stands for
    4.5 s, but over 10 m from any intersection; scene-0796: it drives at 11-15 m/s throughout."""
    name = "ego_waiting_at_intersection"
    assert track(NUSC.format("0061"), "ego").speed.min() > 0.6
    check_negative(name, NUSC.format("0061"))
    ego = track(AV2_START, "ego")
    standing = ego.speed < WAIT_SPEED_MPS
    assert standing[:45].all() and distance_to_intersection(AV2_START, ego)[standing].min() > WAIT_DISTANCE_M
    check_negative(name, AV2_START)
    check_negative(name, NUSC.format("0796"))


# ---------------------------------------------------------------- a moving vehicle near an intersection
def near_at(relative: str, frame: int) -> tuple[set[str], set[str]]:
    """The vehicles near an intersection at ``frame``: by the truth, and by the query."""
    name = "vehicle_near_intersection"
    true = {k.rsplit("@", 1)[0] for k in truth(name, relative) if k.endswith(f"@{frame}")}
    return true, {k.rsplit("@", 1)[0] for k in found(name, relative) if k.endswith(f"@{frame}")}


def test_vehicle_near_intersection_positives():
    """nuScenes scene-0916 frames 75-83: bus 8a26f7d3 drives at 3.8 m/s 0.3-0.9 m from the
    intersection (its centre is off Scenic's `road`, hence `in everywhere`); nuScenes scene-0061
    frame 0: car c1958768 at 5.3 m/s in the intersection; Waymo motion_data_one_scenario frame 0:
    car 1675, 6 m/s in the intersection."""
    relative = NUSC.format("0916")
    bus = track(relative, "8a26f7d3")
    at = (bus.frame >= 75) & (bus.frame <= 83)
    assert (bus.speed[at] > 3.5).all() and (distance_to_intersection(relative, bus)[at] < 1).all()
    for f in range(75, 84):
        true, answered = near_at(relative, f)
        assert bus.id in true and bus.id in answered, f
    for relative, prefix in ((NUSC.format("0061"), "c1958768"), (WAYMO_ONE, "1675")):
        tr = track(relative, prefix)
        assert tr.frame[0] == 0 and tr.speed[0] > 5 and distance_to_intersection(relative, tr)[0] == 0
        true, answered = near_at(relative, 0)
        assert tr.id in true and tr.id in answered


def test_vehicle_near_intersection_negatives():
    """CommonRoad US101-3_3 and Lanker-1_1 have no intersection on their maps: no vehicle; nuScenes
    scene-0916 frames 160-169: every vehicle within 5 m of the intersection moves below 0.3 m/s."""
    name = "vehicle_near_intersection"
    check_negative(name, US101)
    check_negative(name, LANKER)
    relative = NUSC.format("0916")
    for f in range(160, 170):
        assert near_at(relative, f) == (set(), set())
    slow = [
        tr.speed[tr.frame == f].max()
        for tr in (recording(relative)[2][i] for i in vehicles(relative))
        for f in range(160, 170)
        if ((tr.frame == f) & (distance_to_intersection(relative, tr) < NEAR_DISTANCE_M)).any()
    ]
    assert slow and max(slow) < 0.3


# ---------------------------------------------------------------- a vehicle reversing
def test_vehicle_reversing_positives():
    """AV2 7fab2350 car 688118c3 moves backwards, against its heading, at 0.4-0.8 m/s over frames
    86-132; AV2 adcf7d18 truck 8dbb0a29 backs up at up to 1.1 m/s over frames 73-93; nuScenes
    scene-1077 truck f8feea7f creeps backwards at 0.3-0.6 m/s over frames 150-189."""
    name = "vehicle_reversing"
    car = track(AV2_STOP, "688118c3")
    along = car.at(car.along)
    assert max(along[f] for f in range(95, 116)) < -0.4
    check_positive(name, AV2_STOP, "688118c3", (91, 125))
    truck = track(AV2_START, "8dbb0a29")
    assert truck.kind == "truck" and truck.along.min() < -1.1
    check_positive(name, AV2_START, "8dbb0a29", (73, 93))
    check_positive(name, NUSC.format("1077"), "f8feea7f", (150, 189))


def test_vehicle_reversing_negatives():
    """AV2 7fab2350 car d4af6dfe drives forwards (dips below -0.3 m/s for under 2 s, around frame
    130); AV2 forecasting car 139310 is parked with jittery positions (speeds along its heading
    swinging between -3.6 and +3.7 m/s, never below -0.3 m/s for 2 s); no vehicle on nuScenes
    scene-0061 moves backwards."""
    name = "vehicle_reversing"
    check_negative(name, AV2_STOP, "d4af6dfe")
    forecasting = "av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151"
    parked = track(forecasting, "139310")
    assert parked.along.min() < -3 and parked.along.max() > 3
    check_negative(name, forecasting, "139310")
    check_negative(name, NUSC.format("0061"))


# ---------------------------------------------------------------- ego turning right at an intersection
def test_ego_turning_right_at_intersection_positives():
    """nuScenes scene-0916: the ego turns right through the intersection (-1.46 rad in 4 s around
    frame 77); Waymo womd_scenario_input: its ego 2893 turns right (-0.69 rad around frame 70)."""
    name = "ego_turning_right_at_intersection"
    assert largest_turn(track(NUSC.format("0916"), "ego"), -1) > 1.4
    check_positive(name, NUSC.format("0916"), "*", (60, 83))
    assert largest_turn(track(WAYMO_INPUT, "2893"), -1) > 0.6
    check_positive(name, WAYMO_INPUT, "*", (55, 77))


def test_ego_turning_right_at_intersection_negatives():
    """nuScenes scene-0061: the ego turns left only; scene-0553: it stands; AV2 7fab2350: left only
    (largest right turn below 0.2 rad)."""
    name = "ego_turning_right_at_intersection"
    assert largest_turn(track(NUSC.format("0061"), "ego"), -1) < 0.1
    check_negative(name, NUSC.format("0061"))
    check_negative(name, NUSC.format("0553"))
    assert largest_turn(track(AV2_STOP, "ego"), -1) < 0.2
    check_negative(name, AV2_STOP)


# ---------------------------------------------------------------- TP / FP / FN / TN over the 20 recordings
COUNTS = {
    "vehicle_turning_left_at_intersection": {"TP": 14, "FP": 2, "FN": 0, "TN": 891},
    "vehicle_turning_right": {"TP": 25, "FP": 1, "FN": 2, "TN": 963},
    "ego_turning_left_following_vehicle": {"TP": 3, "FP": 0, "FN": 0, "TN": 17},
    "ego_waiting_at_intersection": {"TP": 5, "FP": 0, "FN": 1, "TN": 14},
    "vehicle_near_intersection": {"TP": 12716, "FP": 29, "FN": 187, "TN": 64825},
    "vehicle_reversing": {"TP": 3, "FP": 0, "FN": 1, "TN": 987},
    "ego_turning_right_at_intersection": {"TP": 2, "FP": 0, "FN": 0, "TN": 18},
}
"""Units: objects (vehicle situations: every car, or every vehicle, other than the ego of every
recording), recordings (ego situations) and (recording, frame) pairs (vehicle_near_intersection)."""


def just_under_threshold(relative: str, prefix: str, sign: int) -> None:
    """The object turns that way by more than the labeller's 0.44 rad but less than the truth's
    0.6 rad in 4 s: a gentle turn only one side calls a turn."""
    assert 0.44 < largest_turn(track(relative, prefix), sign) < TURN_RAD


def right_turn_far_from_intersection(relative: str, prefix: str, sign: int) -> None:
    """A right turn of over 1.2 rad that the labeller does not count: the car turns into a side
    road 7.7 m and more from the intersection, some 4 s after leaving it (the labeller counts
    turns only within 3 s of an intersection, and a 2 s window needs the label throughout)."""
    tr = track(relative, prefix)
    during = (tr.frame >= 60) & (tr.frame <= 130)
    assert largest_turn(tr, sign) > 1.2 and distance_to_intersection(relative, tr)[during].min() > 7.5


def heading_flip(relative: str, prefix: str, sign: int) -> None:
    """Label noise, not a turn: the heading jumps by over 3 rad between two frames."""
    assert np.abs(np.diff(np.unwrap(track(relative, prefix).heading))).max() > 3


def slow_creep(relative: str, prefix: str, sign: int) -> None:
    """Backwards at 0.3-0.66 m/s (at most 0.55 m/s over any 2 s): the labeller's Reverse (-0.48
    m/s after 1 s smoothing) holds for 1.2 s only, under the query's 1.5 s window."""
    tr = track(relative, prefix)
    mean = np.convolve(tr.along, np.ones(WINDOW) / WINDOW, "valid")
    assert -0.6 < mean.min() < REVERSE_MPS and tr.along.min() > -0.7


def recorded_speed_moves(relative: str, prefix: str, sign: int) -> None:
    """Standing by its positions (under 0.5 m/s) but not by its recorded velocity (over 1 m/s at a
    frame of its wait), which the query reads."""
    tr = track(relative, prefix)
    (span,) = truth("ego_waiting_at_intersection", relative)[tr.id]
    during = (tr.frame >= span[0]) & (tr.frame <= span[1])
    assert tr.speed[during].max() < WAIT_SPEED_MPS and tr.recorded_speed[during].max() > 1


DISAGREEMENTS = {
    "vehicle_turning_left_at_intersection": {
        ("FP", AV2_START, "ae2af6f2"): just_under_threshold,
        ("FP", NUSC.format("1077"), "6cec6965"): just_under_threshold,
    },
    "vehicle_turning_right": {
        ("FP", NUSC.format("0103"), "045cd82a"): just_under_threshold,
        ("FN", AV2_START, "41269c43"): right_turn_far_from_intersection,
        ("FN", WAYMO_INPUT, "916"): heading_flip,
    },
    "ego_waiting_at_intersection": {("FN", PEACH, "564"): recorded_speed_moves},
    "vehicle_reversing": {("FN", AV2_STOP, "16c75c92"): slow_creep},
}
"""Every object- or recording-level disagreement, with the raw-number check of its reason."""
NEAR_REASONS = {"FP": Counter({"speed": 29}), "FN": Counter({"last": 154, "speed": 33})}


@pytest.mark.parametrize("name", NAMES)
def test_counts(name):
    """The situation's TP/FP/FN/TN against the raw-data truth, and the reason of every
    disagreement checked on the raw numbers."""
    cells = confusion(name)
    assert {cell: len(units) for cell, units in cells.items()} == COUNTS[name]
    if name == "vehicle_near_intersection":
        check_near_disagreements(cells)
        return
    sign = -1 if "right" in name else 1
    expected = DISAGREEMENTS.get(name, {})
    actual = set()
    for cell in ("FP", "FN"):
        for relative, unit in cells[cell]:
            if name.startswith("ego_"):
                unit = next(iter(truth(name, relative) or found(name, relative)))
            actual.add(next((c, r, p) for c, r, p in expected if (c, r) == (cell, relative) and unit.startswith(p)))
    assert actual == set(expected)
    for (_, relative, prefix), reason in expected.items():
        reason(relative, prefix, sign)


def near_reason(relative: str, unit: str, cell: str) -> str:
    """Why the query and the truth disagree on one (vehicle, frame) of vehicle_near_intersection:
    'speed' (the recording's velocity columns, which the query reads, and its positions'
    differences, which the truth reads, fall on either side of 1 m/s: nuScenes' velocities are
    constant between its 2 Hz keyframes, AV2 forecasting's parked cars jitter by ~1 m/s),
    'last' (the vehicle is not observed at the next frame, which the query's two-frame window
    needs), or '' (unexplained)."""
    object_id, frame = unit.rsplit("@", 1)
    tr, f = recording(relative)[2][object_id], int(frame)
    at = int(np.flatnonzero(tr.frame == f)[0])
    speed, recorded = tr.speed[at], tr.recorded_speed[at]
    if cell == "FN" and f + 1 not in set(tr.frame.tolist()):
        return "last"
    if (cell == "FP") == (speed <= NEAR_SPEED_MPS < recorded) or (cell == "FN") == (recorded <= NEAR_SPEED_MPS < speed):
        return "speed"
    return ""


def check_near_disagreements(cells: dict[str, list[tuple[str, str]]]) -> None:
    """Every (vehicle, frame) disagreement of vehicle_near_intersection has its reason."""
    reasons = {cell: Counter(near_reason(r, unit, cell) for r, unit in cells[cell]) for cell in ("FP", "FN")}
    assert reasons == NEAR_REASONS


@pytest.fixture(autouse=True)
def _shared(real_data) -> None:
    """Skip when ../shared/real_data is absent."""
