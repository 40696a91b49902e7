"""Kinematics derived from positions over time, vectorised over all objects and frames."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .geometry import heading_difference, heading_of_vector
from .states import StateTable


ESTIMATED_VELOCITY = "velocity_estimated_from"
"""Trace attribute of a reader that fills velocities the data lacks by :func:`with_derived_velocity`
(its value says from what): queries read such velocities as the trace's, and name the estimate
where it is missing (a track's lone frame)."""


def track_order(states: StateTable) -> np.ndarray:
    """Permutation of state rows that groups them by object, in frame order within an object."""
    return np.lexsort((states.frame, states.object))


def finite_difference(
    states: StateTable, frame_time: np.ndarray, columns: tuple[np.ndarray, ...], max_gap_s: float = 1.0
) -> tuple[np.ndarray, ...]:
    """Time derivative (units of ``columns`` per second) of per-state-row values along each track.

    Central differences inside a track, one-sided at its ends; a neighbour more than
    ``max_gap_s`` seconds away (a gap in the track) is not used. Rows with no usable
    neighbour get NaN, and so do rows whose difference reads a NaN value.
    """
    order = track_order(states)
    obj = states.object[order]
    t = frame_time[states.frame[order]]
    values = np.stack([column[order] for column in columns], axis=1)
    same_next = np.zeros(len(order), dtype=bool)
    same_next[:-1] = (obj[1:] == obj[:-1]) & (np.diff(t) <= max_gap_s) & (np.diff(t) > 0)
    same_prev = np.zeros(len(order), dtype=bool)
    same_prev[1:] = same_next[:-1]
    idx = np.arange(len(order))
    nxt = np.where(same_next, idx + 1, idx)
    prv = np.where(same_prev, np.maximum(idx - 1, 0), idx)
    dt = t[nxt] - t[prv]
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = (values[nxt] - values[prv]) / dt[:, None]
    rate[dt <= 0] = np.nan
    out = np.empty_like(rate)
    out[order] = rate
    return tuple(out[:, k] for k in range(len(columns)))


def finite_difference_velocity(
    states: StateTable, frame_time: np.ndarray, max_gap_s: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Velocity (vx, vy) in m/s of every state row: :func:`finite_difference` of its positions."""
    vx, vy = finite_difference(states, frame_time, (states.x, states.y), max_gap_s)
    return vx, vy


def finite_difference_acceleration(
    states: StateTable, frame_time: np.ndarray, max_gap_s: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Acceleration (ax, ay) in m/s² of every state row, map frame: :func:`finite_difference` of its
    velocities (NaN where a velocity it reads is NaN)."""
    ax, ay = finite_difference(states, frame_time, (states.vx, states.vy), max_gap_s)
    return ax, ay


def with_derived_velocity(states: StateTable, frame_time: np.ndarray) -> StateTable:
    """The states with NaN velocities filled in from finite differences of positions."""
    missing = np.isnan(states.vx) | np.isnan(states.vy)
    if not missing.any():
        return states
    vx, vy = finite_difference_velocity(states, frame_time)
    return replace(states, vx=np.where(missing, vx, states.vx), vy=np.where(missing, vy, states.vy))


def heading_motion_error(states: StateTable, frame_time: np.ndarray, min_speed: float = 2.0) -> np.ndarray:
    """Absolute angle (radians) between each state's heading and its direction of motion,
    for rows moving faster than ``min_speed`` m/s (by finite differences); NaN elsewhere."""
    vx, vy = finite_difference_velocity(states, frame_time)
    speed = np.hypot(vx, vy)
    err = np.abs(heading_difference(states.heading, heading_of_vector(vx, vy)))
    return np.where(speed > min_speed, err, np.nan)
