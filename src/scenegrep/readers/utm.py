"""WGS84 latitude/longitude to UTM and to Autoware's MGRS-local metres (no pyproj).

UTM is the transverse Mercator projection of the WGS84 ellipsoid (scale 0.9996 on the central
meridian, false easting 500 km, false northing 10,000 km south of the equator), computed with
Krüger's series to sixth order in the third flattening n (Karney, "Transverse Mercator with an
accuracy of a few nanometers", J. Geodesy 85, 2011, eqs. 7-9 and 35), accurate to well under a
millimetre within a zone. The zone follows the UTM rules including the Norway and Svalbard
exceptions; polar latitudes (above 84 N or below 80 S, where MGRS uses UPS) are refused.

Autoware's default map projector (MGRS) puts a map in the 100 km MGRS grid square of its points:
local x and y are the UTM easting and northing less the south-west corner of that square. Here
every point of a map is projected in the zone of its first point and made local to the first
point's square, so the coordinates stay continuous across square edges.
"""

from __future__ import annotations

import numpy as np

A_WGS84 = 6378137.0
F_WGS84 = 1 / 298.257223563
K0 = 0.9996
FALSE_EASTING = 500_000.0
FALSE_NORTHING_SOUTH = 10_000_000.0
MGRS_SQUARE_M = 100_000.0

_N = F_WGS84 / (2 - F_WGS84)
_E = np.sqrt(F_WGS84 * (2 - F_WGS84))
_RECTIFYING_RADIUS = A_WGS84 / (1 + _N) * (1 + _N**2 / 4 + _N**4 / 64 + _N**6 / 256)
_ALPHA = np.array(
    [
        _N / 2 - 2 * _N**2 / 3 + 5 * _N**3 / 16 + 41 * _N**4 / 180 - 127 * _N**5 / 288 + 7891 * _N**6 / 37800,
        13 * _N**2 / 48 - 3 * _N**3 / 5 + 557 * _N**4 / 1440 + 281 * _N**5 / 630 - 1983433 * _N**6 / 1935360,
        61 * _N**3 / 240 - 103 * _N**4 / 140 + 15061 * _N**5 / 26880 + 167603 * _N**6 / 181440,
        49561 * _N**4 / 161280 - 179 * _N**5 / 168 + 6601661 * _N**6 / 7257600,
        34729 * _N**5 / 80640 - 3418889 * _N**6 / 1995840,
        212378941 * _N**6 / 319334400,
    ]
)


def utm_zone(lat: float, lon: float) -> int:
    """The UTM zone (1-60) of a point (degrees), with the Norway and Svalbard exceptions."""
    zone = int(np.floor((lon + 180.0) / 6.0)) % 60 + 1
    if 56.0 <= lat < 64.0 and 3.0 <= lon < 12.0:
        return 32
    if 72.0 <= lat < 84.0 and 0.0 <= lon < 42.0:
        return 31 if lon < 9.0 else 33 if lon < 21.0 else 35 if lon < 33.0 else 37
    return zone


def to_utm(lat: np.ndarray, lon: np.ndarray, zone: int, north: bool) -> tuple[np.ndarray, np.ndarray]:
    """Easting and northing (m) of points (degrees) in a UTM ``zone`` of the ``north`` or south
    hemisphere."""
    phi = np.radians(np.asarray(lat, dtype=np.float64))
    lam = np.radians(np.asarray(lon, dtype=np.float64) - (6.0 * zone - 183.0))
    lam = (lam + np.pi) % (2 * np.pi) - np.pi
    sin_phi = np.sin(phi)
    tau = np.sinh(np.arctanh(sin_phi) - _E * np.arctanh(_E * sin_phi))
    xi_prime = np.arctan2(tau, np.cos(lam))
    eta_prime = np.arcsinh(np.sin(lam) / np.hypot(tau, np.cos(lam)))
    j = 2.0 * np.arange(1, len(_ALPHA) + 1)[:, None]
    xi = xi_prime + (_ALPHA[:, None] * np.sin(j * xi_prime) * np.cosh(j * eta_prime)).sum(axis=0)
    eta = eta_prime + (_ALPHA[:, None] * np.cos(j * xi_prime) * np.sinh(j * eta_prime)).sum(axis=0)
    easting = FALSE_EASTING + K0 * _RECTIFYING_RADIUS * eta
    northing = K0 * _RECTIFYING_RADIUS * xi + (0.0 if north else FALSE_NORTHING_SOUTH)
    return easting, northing


def to_mgrs_local(lat: np.ndarray, lon: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """x and y (m) of points (degrees) in the 100 km MGRS square of the first point, in its UTM
    zone (see the module docstring); ValueError for a polar or out-of-range latitude or longitude."""
    lat = np.asarray(lat, dtype=np.float64)
    lon = np.asarray(lon, dtype=np.float64)
    if not (np.all(np.isfinite(lat)) and np.all(np.isfinite(lon))):
        raise ValueError("a latitude or longitude is not a finite number")
    if np.any(lat < -80.0) or np.any(lat > 84.0) or np.any(np.abs(lon) > 180.0):
        raise ValueError("a latitude outside [-80, 84] degrees (UTM) or a longitude outside [-180, 180]")
    zone = utm_zone(float(lat[0]), float(lon[0]))
    easting, northing = to_utm(lat, lon, zone, bool(lat[0] >= 0.0))
    corner_e = np.floor(easting[0] / MGRS_SQUARE_M) * MGRS_SQUARE_M
    corner_n = np.floor(northing[0] / MGRS_SQUARE_M) * MGRS_SQUARE_M
    return easting - corner_e, northing - corner_n
