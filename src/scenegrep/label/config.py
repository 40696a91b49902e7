"""The labeller's thresholds (:file:`thresholds.toml`, documented there with units).

:func:`load_config` reads the shipped file, or a user's file in the same layout; every key
must be present and of the right shape, and an error names the file and the key.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from ..errors import UserError, at

DEFAULT_CONFIG = Path(__file__).with_name("thresholds.toml")

Ramp = tuple[float, float]
"""(a, b): confidence 0 at a and 1 at b, linear between, clipped outside."""


@dataclass(frozen=True)
class LabelsConfig:
    min_confidence: float


@dataclass(frozen=True)
class TracksConfig:
    max_gap_s: float
    smooth_s: float
    unknown_confidence: float


@dataclass(frozen=True)
class VehicleConfig:
    stationary_speed_mps: Ramp
    brake_accel_mps2: Ramp
    accelerate_accel_mps2: Ramp
    reverse_speed_mps: Ramp
    follow_heading_rad: Ramp
    off_lane_follow: float
    lane_change_lateral_mps: Ramp
    lane_change_event_s: float
    lane_change_sustained_mps: Ramp
    lane_change_event_lateral_mps: Ramp
    lane_change_yaw_rate_radps: Ramp
    no_neighbour_factor: float
    turn_heading_change_rad: Ramp
    turn_window_s: float
    turn_intersection_margin_s: float


@dataclass(frozen=True)
class PedestrianConfig:
    stationary_speed_mps: Ramp
    cross_angle_rad: Ramp
    off_lane_cross: float


@dataclass(frozen=True)
class LabelConfig:
    """All thresholds, one section per table of the TOML file."""

    labels: LabelsConfig
    tracks: TracksConfig
    vehicle: VehicleConfig
    pedestrian: PedestrianConfig


def load_config(path: str | Path | None = None) -> LabelConfig:
    """The thresholds of ``path`` (default: the shipped :data:`DEFAULT_CONFIG`)."""
    path = Path(path) if path is not None else DEFAULT_CONFIG
    try:
        document = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise UserError(f"cannot read the labeller configuration: {exc.strerror}", at(path)) from None
    except tomllib.TOMLDecodeError as exc:
        raise UserError(f"not a TOML file: {exc}", at(path)) from None
    unknown = set(document) - set(_SECTIONS)
    if unknown:
        raise UserError(f"unknown table [{sorted(unknown)[0]}]", at(path))
    return LabelConfig(**{name: _section(path, document, name, kind) for name, kind in _SECTIONS.items()})


_SECTIONS: dict[str, type] = {
    "labels": LabelsConfig,
    "tracks": TracksConfig,
    "vehicle": VehicleConfig,
    "pedestrian": PedestrianConfig,
}


def _section(path: Path, document: dict[str, Any], name: str, kind: type) -> Any:
    table = document.get(name)
    if not isinstance(table, dict):
        raise UserError(f"missing table [{name}]", at(path))
    unknown = set(table) - {f.name for f in fields(kind)}
    if unknown:
        raise UserError(f"unknown key {name}.{sorted(unknown)[0]}", at(path))
    return kind(**{f.name: _value(path, f"{name}.{f.name}", table.get(f.name), f.type) for f in fields(kind)})


def _value(path: Path, key: str, value: Any, kind: str) -> float | Ramp:
    if value is None:
        raise UserError(f"missing key {key}", at(path))
    if kind == "Ramp":
        if not (isinstance(value, list) and len(value) == 2 and all(_is_number(v) for v in value)):
            raise UserError(f"{key} must be a pair of numbers [a, b]", at(path))
        if value[0] == value[1]:
            raise UserError(f"{key} must have two different ends", at(path))
        return (float(value[0]), float(value[1]))
    if not _is_number(value):
        raise UserError(f"{key} must be a number", at(path))
    return float(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
