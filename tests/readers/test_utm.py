"""The UTM / MGRS-local projection of Lanelet2 maps' lat/lon: a published grid position, the
central meridian against the meridian arc integrated numerically, conformality (equal scale
north and east, right angles kept) by finite differences, zones, MGRS squares."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from scenegrep.readers.utm import A_WGS84, F_WGS84, K0, to_mgrs_local, to_utm, utm_zone

E2 = F_WGS84 * (2 - F_WGS84)


def meridian_arc(lat_deg: float) -> float:
    """Distance (m) along the WGS84 meridian from the equator to ``lat_deg``, by quadrature."""
    radius = lambda phi: A_WGS84 * (1 - E2) / (1 - E2 * math.sin(phi) ** 2) ** 1.5  # noqa: E731
    return quad(radius, 0.0, math.radians(lat_deg), epsabs=1e-6, epsrel=1e-11, limit=200)[0]


def test_cn_tower_grid_position():
    """Wikipedia's UTM example: the CN Tower (43°38'33.24"N 79°23'13.7"W) is at 17T 630084 m E,
    4833438 m N (grid positions truncate to the metre)."""
    lat, lon = 43 + 38 / 60 + 33.24 / 3600, -(79 + 23 / 60 + 13.7 / 3600)
    assert utm_zone(lat, lon) == 17
    easting, northing = to_utm(np.array([lat]), np.array([lon]), 17, True)
    assert (math.floor(easting[0]), math.floor(northing[0])) == (630084, 4833438)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")  # quad on subnormal latitudes
@settings(max_examples=25)
@given(lat=st.floats(-80, 84), zone=st.integers(1, 60))
def test_central_meridian_is_the_scaled_meridian_arc(lat, zone):
    easting, northing = to_utm(np.array([lat]), np.array([6.0 * zone - 183.0]), zone, lat >= 0)
    assert easting[0] == pytest.approx(500_000.0, abs=1e-6)
    expected = K0 * meridian_arc(lat) + (0.0 if lat >= 0 else 10_000_000.0)
    assert northing[0] == pytest.approx(expected, abs=1e-4)


@settings(max_examples=25)
@given(lat=st.floats(-79, 83), offset=st.floats(-3.5, 3.5))
def test_conformal(lat, offset):
    """Transverse Mercator is conformal: a small step north and one east (each scaled by the
    ellipsoid's radii there) map to perpendicular grid steps of equal length."""
    h = 1e-5
    phi = math.radians(lat)
    north_len = A_WGS84 * (1 - E2) / (1 - E2 * math.sin(phi) ** 2) ** 1.5 * math.radians(h)
    east_len = A_WGS84 / math.sqrt(1 - E2 * math.sin(phi) ** 2) * math.cos(phi) * math.radians(h)
    lats = np.array([lat - h / 2, lat + h / 2, lat, lat])
    lons = 3.0 + offset + np.array([0, 0, -h / 2, h / 2])
    x, y = to_utm(lats, lons, 31, True)
    north = np.array([x[1] - x[0], y[1] - y[0]]) / north_len
    east = np.array([x[3] - x[2], y[3] - y[2]]) / east_len
    assert np.hypot(*north) == pytest.approx(np.hypot(*east), rel=1e-7)
    assert abs(np.dot(north, east)) / np.hypot(*north) ** 2 < 1e-7


@pytest.mark.parametrize(
    "lat, lon, zone",
    [
        (0, -180, 1),
        (0, 179.9, 60),
        (48.1, 11.6, 32),
        (60, 5, 32),
        (60, 2.9, 31),
        (78, 8, 31),
        (78, 10, 33),
        (78, 40, 37),
    ],
)
def test_zones(lat, lon, zone):
    assert utm_zone(lat, lon) == zone


def test_mgrs_local_is_within_the_first_points_square_and_continuous():
    lat = np.array([35.6812, 35.6812, 35.7])
    lon = np.array([139.7671, 139.7672, 139.7671])
    x, y = to_mgrs_local(lat, lon)
    easting, northing = to_utm(lat, lon, 54, True)
    assert 0 <= x[0] < 100_000 and 0 <= y[0] < 100_000
    np.testing.assert_allclose(np.diff(x), np.diff(easting), atol=1e-6)
    np.testing.assert_allclose(np.diff(y), np.diff(northing), atol=1e-6)
    assert x[0] == pytest.approx(easting[0] % 100_000, abs=1e-6)


@pytest.mark.parametrize("lat, lon", [(85.0, 0.0), (-81.0, 0.0), (0.0, 181.0), (math.nan, 0.0), (0.0, math.inf)])
def test_refuses_polar_and_invalid(lat, lon):
    with pytest.raises(ValueError):
        to_mgrs_local(np.array([lat]), np.array([lon]))
