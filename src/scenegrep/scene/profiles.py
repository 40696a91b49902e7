"""Tolerance profiles: named tolerances measured on each dataset's labels.

``benchmarks/label_noise.py`` measures, per dataset of ``../shared/real_data``, how far real
labels are from what Scenic's defaults make exact, and derives each profile: the heading
tolerance admits 90 % of moving vehicles' deviations from their lane's direction, the position
tolerance 90 % of the lateral offsets of a vehicle ahead of another in its lane from that one's
axis (and 90 % of the labels' frame-to-frame jitter and size changes, smaller everywhere), the
speed tolerance 90 % of the differences between labelled velocities and the tracks' own finite
differences, each rounded up to two significant digits; the README tabulates the measurements. ``exact`` is the
default (PRODUCT.md: exact semantics unless the user widens a tolerance).
"""

from __future__ import annotations

from dataclasses import fields, replace

from ..errors import UserError
from .tolerance import Tolerance

PROFILES: dict[str, Tolerance] = {
    "exact": Tolerance(),
    "av2": Tolerance(position=1.3, heading=0.086, speed=1.3),
    "nuscenes": Tolerance(position=1.4, heading=0.084, speed=0.011),
    "waymo": Tolerance(position=0.83, heading=0.049, speed=0.19),
    "commonroad": Tolerance(position=1.2, heading=0.051, speed=0.32),
}


def tolerance_of(profile: str | None = None, **given: float | None) -> Tolerance:
    """The tolerances of ``profile`` (None: exact) with each tolerance given by name (a field of
    :class:`Tolerance`: position in m, heading in rad, speed in m/s) instead of the profile's; None means not
    given. UserError for an unknown profile or a negative tolerance."""
    if profile is not None and profile not in PROFILES:
        raise UserError(f"unknown tolerance profile {profile!r}; choose one of {', '.join(PROFILES)}")
    names = {f.name for f in fields(Tolerance)}
    unknown = set(given) - names
    if unknown:
        raise UserError(f"unknown tolerance {sorted(unknown)[0]!r}; the tolerances are {', '.join(sorted(names))}")
    chosen = replace(PROFILES[profile or "exact"], **{k: v for k, v in given.items() if v is not None})
    return Tolerance.checked(**{name: getattr(chosen, name) for name in names})
