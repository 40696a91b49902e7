"""Confidences of the primitive behaviours from the evidence (:mod:`.evidence`), by kind of object.

Every confidence is a product of ramps (:data:`~.config.Ramp`) over the evidence, in [0, 1]:

* vehicles (cars, trucks, buses, trailers, motorcycles): ``Stationary`` by the speed; moving is
  its complement. ``LaneChangeLeft``/``Right`` by the speed across the lane towards the vehicle's
  left or right (or a lane-id change to the same-direction neighbour on that side within
  ``lane_change_event_s``, with some lateral speed; sides as in :mod:`.evidence`), while
  moving and outside intersections, reduced where that side has no same-direction lane; the speed
  across must also be sustained on average over ``lane_change_event_s`` either side (noise is not)
  and, unless the lane id changes nearby, the path nearly straight (curves read as lateral motion).
  ``FollowLane`` while moving, aligned with the lane, not changing lanes and not reversing.
  ``TurnLeft``/``Right`` by the heading change over ``turn_window_s`` near an intersection (anywhere
  on a map without intersections): counter-clockwise (the heading grows) is left, clockwise right,
  so the two never hold together and a turn in Scenic's sense is exactly one of them. ``Brake`` and
  ``Accelerate`` by the longitudinal acceleration while moving; ``Reverse`` by the speed along
  the object's own heading.
* pedestrians, cyclists and animals: ``Stationary`` by the speed, ``Walk`` its complement,
  ``Cross`` walking in a crosswalk, or across a lane's direction on it (or anywhere else on the
  drivable area, reduced). On a map that does not publish crosswalks, an observation whose
  ``Cross`` confidence depends on whether it is in one (walking, not fully crossing by the lane
  evidence) is an error unless the user chose how to treat the unknown layer
  (:class:`~scenegrep.model.layers.UnknownLayers`: in a crosswalk everywhere, or nowhere); those
  observations are counted as decisions the choice affected. :func:`confidences` returns them as
  a mask; :func:`decide_crossings` raises or counts for the observations a caller hands out (the
  online labeller scores a history many times but counts each observation once).
* anything else (static objects): ``Stationary`` by the vehicle speed ramp.

A track with no usable speed (a single observation) gets ``[tracks].unknown_confidence`` for
Stationary and for moving. :data:`SCENIC_LABELS` says which labels stand for Scenic's library
behaviours: a program's ``LaneChangeBehavior`` is seen here as LaneChangeLeft or Right.
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import heading_difference
from ..model.taxonomy import VEHICLE_KINDS
from ..model.layers import UnknownLayers
from .config import LabelConfig, PedestrianConfig, Ramp, VehicleConfig
from .evidence import Evidence
from .tracks import Tracks

VEHICLE_BEHAVIOURS = (
    "Stationary",
    "FollowLane",
    "LaneChangeLeft",
    "LaneChangeRight",
    "TurnLeft",
    "TurnRight",
    "Brake",
    "Accelerate",
    "Reverse",
)
PEDESTRIAN_BEHAVIOURS = ("Stationary", "Walk", "Cross")
VOCABULARY = tuple(dict.fromkeys(VEHICLE_BEHAVIOURS + PEDESTRIAN_BEHAVIOURS))
"""Every behaviour the labeller emits, in column order."""

WALKING_KINDS = frozenset({"pedestrian", "bicycle", "animal"})
"""Kinds labelled with :data:`PEDESTRIAN_BEHAVIOURS`."""

SCENIC_LABELS = {
    "LaneChange": ("LaneChangeLeft", "LaneChangeRight"),
    "Turn": ("TurnLeft", "TurnRight"),
    "FollowTrajectory": ("FollowLane", "TurnLeft", "TurnRight"),
    "WalkForward": ("Walk",),
    "Crossing": ("Cross",),
}
"""Primitive behaviours of Scenic's driving library (name without ``Behavior``) and the labels
that stand for them here (a lane change is seen with its side; following a trajectory of lanes
is following them, turning where they turn). Other names stand for themselves."""


def ramp(values: np.ndarray, bounds: Ramp) -> np.ndarray:
    """0 at ``bounds[0]``, 1 at ``bounds[1]``, linear between, clipped; NaN stays NaN."""
    low, high = bounds
    return np.clip((values - low) / (high - low), 0.0, 1.0)


def confidences(
    evidence: Evidence, kinds: np.ndarray, tracks: Tracks, config: LabelConfig, everywhere: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """(observations, len(VOCABULARY)) confidences in track order, ``kinds`` per observation, and
    per observation whether its Cross confidence depends on an unknown crosswalk layer (taken to
    be ``everywhere``, else nowhere; :func:`decide_crossings` makes that a decision or an error)."""
    out = np.zeros((len(kinds), len(VOCABULARY)))
    column = {name: k for k, name in enumerate(VOCABULARY)}
    vehicle = np.isin(kinds, list(VEHICLE_KINDS))
    walking = np.isin(kinds, list(WALKING_KINDS))
    unknown = config.tracks.unknown_confidence
    for name, score in _vehicle(evidence, tracks, config.vehicle, unknown).items():
        out[vehicle, column[name]] = score[vehicle]
    walks = _walking(evidence, config.pedestrian, unknown)
    walks["Cross"], depends = _cross(evidence, walks, walking, config.pedestrian, everywhere)
    for name, score in walks.items():
        out[walking, column[name]] = score[walking]
    other = ~(vehicle | walking)
    out[other, column["Stationary"]] = _stationary(evidence.speed, config.vehicle.stationary_speed_mps, unknown)[other]
    return out, depends


def decide_crossings(choice: UnknownLayers, depends: np.ndarray, map_name: str | None) -> None:
    """The user's choice for the observations whose Cross confidence depends on the unknown crosswalk
    layer (``depends``, see :func:`confidences`): an error without a choice, else counted."""
    n = int(np.count_nonzero(depends))
    if n and choice.mode is None:
        needed_by = f"the labeller's Cross rule ({n} observations of walking objects)"
        raise choice.refuse(["crossing"], needed_by, map_name or "?")
    choice.count("crossing", n)


def _stationary(speed: np.ndarray, bounds: Ramp, unknown: float) -> np.ndarray:
    return np.nan_to_num(ramp(speed, bounds), nan=unknown)


def _vehicle(e: Evidence, tracks: Tracks, c: VehicleConfig, unknown: float) -> dict[str, np.ndarray]:
    stationary = _stationary(e.speed, c.stationary_speed_mps, unknown)
    moving = np.where(np.isnan(e.speed), unknown, 1.0 - stationary)
    left, right = _lane_changes(e, tracks, c, moving)
    reverse = np.nan_to_num(ramp(e.along, c.reverse_speed_mps))
    misalignment = np.abs(heading_difference(e.heading, e.lane_heading))
    aligned = np.where(e.lane >= 0, np.nan_to_num(ramp(misalignment, c.follow_heading_rad)), c.off_lane_follow)
    turn = _turn_angle(e, tracks, c)
    return {
        "Stationary": stationary,
        "FollowLane": moving * aligned * (1.0 - np.maximum(left, right)) * (1.0 - reverse),
        "LaneChangeLeft": left,
        "LaneChangeRight": right,
        "TurnLeft": np.nan_to_num(ramp(turn, c.turn_heading_change_rad)),
        "TurnRight": np.nan_to_num(ramp(-turn, c.turn_heading_change_rad)),
        "Brake": moving * np.nan_to_num(ramp(e.accel, c.brake_accel_mps2)),
        "Accelerate": moving * np.nan_to_num(ramp(e.accel, c.accelerate_accel_mps2)),
        "Reverse": reverse,
    }


def _lane_changes(e: Evidence, tracks: Tracks, c: VehicleConfig, moving: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Confidences of a change to the left and to the right lane."""
    half = max(1, tracks.frames(c.lane_change_event_s))
    straight = np.nan_to_num(ramp(np.abs(e.yaw_rate), c.lane_change_yaw_rate_radps), nan=1.0)
    allowed = moving * ~e.in_intersection
    sustained = tracks.window_mean(e.lateral, half)
    sides = []
    for sign, change, has_lane in ((1.0, e.change_left, e.has_left), (-1.0, e.change_right, e.has_right)):
        lateral = sign * e.lateral
        near_change = tracks.window_any(change, half)
        moving_across = ramp(lateral, c.lane_change_lateral_mps) * ramp(sign * sustained, c.lane_change_sustained_mps)
        evidence = np.maximum(
            np.nan_to_num(moving_across) * straight,
            near_change * np.nan_to_num(ramp(lateral, c.lane_change_event_lateral_mps)),
        )
        sides.append(evidence * allowed * np.where(has_lane | near_change, 1.0, c.no_neighbour_factor))
    return sides[0], sides[1]


def _turn_angle(e: Evidence, tracks: Tracks, c: VehicleConfig) -> np.ndarray:
    """Signed heading change (radians, left positive) over a centred window of ``turn_window_s``,
    zero farther than ``turn_intersection_margin_s`` from any intersection on a map that has some."""
    half = max(1, tracks.frames(c.turn_window_s) // 2)
    position = np.arange(len(tracks))
    later = np.minimum(position + half, tracks.end - 1)
    earlier = np.maximum(position - half, tracks.start)
    change = tracks.angle_change(e.heading, e.turns, later, earlier)
    if not e.knows_intersections:
        return change
    near = tracks.window_any(e.in_intersection, max(1, tracks.frames(c.turn_intersection_margin_s)))
    return np.where(near, change, 0.0)


def _walking(e: Evidence, c: PedestrianConfig, unknown: float) -> dict[str, np.ndarray]:
    stationary = _stationary(e.speed, c.stationary_speed_mps, unknown)
    walk = np.where(np.isnan(e.speed), unknown, 1.0 - stationary)
    return {"Stationary": stationary, "Walk": walk}


def _on_road_cross(e: Evidence, c: PedestrianConfig) -> np.ndarray:
    """How much walking here is crossing, by the lane evidence alone (in [0, 1])."""
    across = np.arcsin(np.abs(np.sin(heading_difference(e.motion_heading, e.lane_heading))))
    return np.where(e.lane >= 0, np.nan_to_num(ramp(across, c.cross_angle_rad)), e.on_drivable * c.off_lane_cross)


def _cross(
    e: Evidence, walks: dict[str, np.ndarray], walking: np.ndarray, c: PedestrianConfig, everywhere: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The Cross confidence: walking, in a crosswalk or crossing by the lane evidence, an unknown
    crosswalk layer taken to be ``everywhere`` (else nowhere); and where that assumption decides it
    (observations of walking objects, walking, not fully crossing by the lane evidence)."""
    walk, on_road = walks["Walk"], _on_road_cross(e, c)
    unknown = np.isnan(e.in_crossing)
    depends = unknown & walking & (walk > 0) & (on_road < 1)
    in_crossing = np.where(unknown, 1.0 if everywhere else 0.0, e.in_crossing)
    return walk * np.maximum(in_crossing, on_road), depends
