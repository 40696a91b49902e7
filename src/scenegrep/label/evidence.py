"""The evidence behaviours are read from: kinematics of every track and its relation to the
road map, per observation, in track order (:class:`~.tracks.Tracks`).

Kinematics (smoothed over ``[tracks].smooth_s``): ``speed`` (m/s), ``along`` (speed along the
object's own heading, negative when reversing), ``accel`` (m/s², derivative of the smoothed
speed), ``heading`` (the box heading smoothed along the track, radians, less whole turns: the
track's unwrapped smoothed heading is ``heading + 2π·turns``, ``turns`` an integer per
observation, :meth:`~.tracks.Tracks.turns`), ``yaw_rate`` (rad/s, left positive),
``motion_heading`` (direction of the smoothed velocity). Velocities are the trace's own where
given, else finite differences of positions. Every value reads only the observations of its
windows (:mod:`.tracks`), so a bounded history gives the offline values bit for bit.

Map relations (all absent, i.e. -1/NaN/False, without a map): ``lane`` (index of the map lane
the object is in, the best-aligned where lanes overlap), ``lane_heading`` (that lane's direction
at the point), ``lateral`` (smoothed speed across the lane, m/s, positive towards the object's
left), ``in_intersection``, ``on_drivable``, ``in_crossing`` (1.0 or 0.0; NaN, unknown, on a map
whose format does not publish crosswalks), lane-id changes to a same-direction neighbour on the
object's left or right (``change_left`` / ``change_right``, set at the first observation in the
new lane) and whether the lane has a same-direction neighbour on that side (``has_left`` /
``has_right``). Sides are the object's own: those of the lane's direction when the object faces
along its lane, swapped when it faces against it (a car on the opposing lane, overtaking);
``knows_intersections`` says whether the map has any intersection; ``map_name`` names the map.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import LabelTrace, RoadMap
from ..model.geometry import heading_of_vector
from ..model.kinematics import finite_difference_velocity
from .tracks import Tracks


@dataclass(frozen=True)
class Evidence:
    """Per-observation evidence in track order; see the module docstring for units."""

    speed: np.ndarray
    along: np.ndarray
    accel: np.ndarray
    heading: np.ndarray
    turns: np.ndarray
    yaw_rate: np.ndarray
    motion_heading: np.ndarray
    lane: np.ndarray
    lane_heading: np.ndarray
    lateral: np.ndarray
    in_intersection: np.ndarray
    on_drivable: np.ndarray
    in_crossing: np.ndarray
    change_left: np.ndarray
    change_right: np.ndarray
    has_left: np.ndarray
    has_right: np.ndarray
    knows_intersections: bool
    map_name: str | None


def gather(trace: LabelTrace, road_map: RoadMap | None, tracks: Tracks, smooth_s: float) -> Evidence:
    """The evidence of every observation of ``trace`` (see the module docstring)."""
    half = max(1, tracks.frames(smooth_s) // 2)
    states = trace.states
    order = tracks.order
    vx, vy = _velocity(trace)
    vx, vy = tracks.window_mean(vx[order], half), tracks.window_mean(vy[order], half)
    x, y = states.x[order], states.y[order]
    raw = states.heading[order]
    turns = tracks.turns(raw)
    heading = tracks.angle_mean(raw, turns, half)
    speed = np.hypot(vx, vy)
    along = -np.sin(heading) * vx + np.cos(heading) * vy
    accel = tracks.window_mean(tracks.gradient(speed), half)
    relations = _MapRelations.of(road_map, x, y, heading)
    against = np.cos(heading - relations.lane_heading) < 0
    lane_left = -np.cos(relations.lane_heading) * vx - np.sin(relations.lane_heading) * vy
    lane = tracks.forward_fill(relations.lane)
    previous = tracks.change_from(lane)
    to_left, to_right = relations.is_left_change(previous, lane), relations.is_left_change(lane, previous)
    has_left = relations.neighbour(relations.left, relations.lane) >= 0
    has_right = relations.neighbour(relations.right, relations.lane) >= 0
    return Evidence(
        speed=speed,
        along=along,
        accel=accel,
        heading=heading,
        turns=turns,
        yaw_rate=tracks.window_mean(tracks.gradient(heading, turns), half),
        motion_heading=heading_of_vector(vx, vy),
        lane=relations.lane,
        lane_heading=relations.lane_heading,
        lateral=np.where(against, -lane_left, lane_left),
        in_intersection=relations.in_intersection,
        on_drivable=relations.on_drivable,
        in_crossing=relations.in_crossing,
        change_left=np.where(against, to_right, to_left),
        change_right=np.where(against, to_left, to_right),
        has_left=np.where(against, has_right, has_left),
        has_right=np.where(against, has_left, has_right),
        knows_intersections=road_map is not None
        and bool(road_map.intersections or road_map.lane_is_intersection.any()),
        map_name=None if road_map is None else road_map.name,
    )


def _velocity(trace: LabelTrace) -> tuple[np.ndarray, np.ndarray]:
    states = trace.states
    missing = np.isnan(states.vx) | np.isnan(states.vy)
    if not missing.any():
        return states.vx, states.vy
    vx, vy = finite_difference_velocity(states, trace.frame_time)
    return np.where(missing, vx, states.vx), np.where(missing, vy, states.vy)


@dataclass(frozen=True)
class _MapRelations:
    """Where each point is on the map, and the map's same-direction lane neighbours."""

    lane: np.ndarray
    lane_heading: np.ndarray
    in_intersection: np.ndarray
    on_drivable: np.ndarray
    in_crossing: np.ndarray
    left: np.ndarray
    right: np.ndarray

    @classmethod
    def of(cls, road_map: RoadMap | None, x: np.ndarray, y: np.ndarray, heading: np.ndarray) -> _MapRelations:
        n = len(x)
        if road_map is None or not road_map.lanes:
            none = np.full(n, -1, dtype=np.intp)
            false = np.zeros(n, dtype=bool)
            return cls(none, np.full(n, np.nan), false, false, false, np.zeros(0, np.intp), np.zeros(0, np.intp))
        pairs = road_map.lanes_containing(x, y)
        lane = road_map.lane_at(x, y, heading, pairs=pairs)
        if not road_map.publishes("crossing"):
            crossing = np.full(n, np.nan)
        else:
            crossing = road_map.contains("crossing", x, y).astype(float) if road_map.crosswalks else np.zeros(n)
        return cls(
            lane=lane,
            lane_heading=road_map.lane_direction_at(x, y, lane),
            in_intersection=road_map.in_intersection(x, y, pairs=pairs),
            on_drivable=road_map.contains("drivable", x, y, pairs=pairs),
            in_crossing=crossing,
            left=_neighbours(road_map, "left"),
            right=_neighbours(road_map, "right"),
        )

    @staticmethod
    def neighbour(table: np.ndarray, lane: np.ndarray) -> np.ndarray:
        """The neighbour in ``table`` of each lane index (-1 for none or no lane)."""
        if len(table) == 0:
            return np.full(len(lane), -1, dtype=np.intp)
        return np.where(lane >= 0, table[np.maximum(lane, 0)], -1)

    def is_left_change(self, before: np.ndarray, after: np.ndarray) -> np.ndarray:
        """Whether moving from lane ``before`` to lane ``after`` is a move to the left
        same-direction neighbour (read off either lane's neighbour links)."""
        moved = (before >= 0) & (after >= 0) & (before != after)
        return moved & ((self.neighbour(self.left, before) == after) | (self.neighbour(self.right, after) == before))


def _neighbours(road_map: RoadMap, side: str) -> np.ndarray:
    """Per lane, the index of its same-direction neighbour on ``side`` (-1 for none)."""
    index = road_map.lane_index
    out = np.full(len(road_map.lanes), -1, dtype=np.intp)
    for i, lane in enumerate(road_map.lanes):
        link = getattr(lane, side)
        if link is not None and link.same_direction and link.lane in index:
            out[i] = index[link.lane]
    return out
