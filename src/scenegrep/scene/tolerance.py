"""The tolerances labelled features are compared with, per kind of feature (a feature of the
program and its labelled value agree when they differ by at most the tolerance)."""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import UserError
from .program import ANGULAR_SPEED_FEATURE, SPEED_FEATURES, Feature


@dataclass(frozen=True)
class Tolerance:
    """Per-feature tolerances: positions and sizes in metres, headings in radians (angular speeds
    in radians per second), speeds and velocity components in metres per second."""

    position: float = 1e-6
    heading: float = 1e-6
    speed: float = 1e-6

    def of(self, feature: Feature) -> float:
        """The tolerance a feature is compared with."""
        return float(getattr(self, self.name_of(feature)))

    @staticmethod
    def name_of(feature: Feature) -> str:
        """The name of the tolerance (a field of this class) a feature is compared with: speed for
        speeds and velocity components, heading for headings and angular speeds, else position."""
        if feature.name in SPEED_FEATURES:
            return "speed"
        return "heading" if feature.is_angle or feature.name == ANGULAR_SPEED_FEATURE else "position"

    @classmethod
    def checked(cls, position: float, heading: float, speed: float = 1e-6) -> Tolerance:
        """Tolerances a user gave (UserError if any is negative)."""
        if position < 0 or heading < 0 or speed < 0:
            raise UserError("tolerances must not be negative")
        return cls(position, heading, speed)
