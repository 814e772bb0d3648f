"""Latitude, longitude and altitude to a local NED frame (WGS-84), exactly, through earth-fixed coordinates.

A point's earth-centred earth-fixed (ECEF) position on the WGS-84 ellipsoid is

.. math:: r = \\big((N + h)\\cos\\varphi\\cos\\lambda,\\; (N + h)\\cos\\varphi\\sin\\lambda,\\;
          (N(1 - e^2) + h)\\sin\\varphi\\big), \\qquad N = a / \\sqrt{1 - e^2 \\sin^2\\varphi}

and its NED coordinates about an origin ``(φ₀, λ₀, h₀)`` are ``C (r − r₀)`` with the rows of ``C``
the origin's north, east and down directions. Over a flight of a few hundred metres this differs
from the flat-earth shortcut ``(Δφ R_M, Δλ R_N cos φ₀, −Δh)`` by millimetres; it is used because it is
exact and no longer.

Where magnetic north lies there, the declination, comes from the World Magnetic Model (NOAA and
the British Geological Survey, public domain; pygeomag's coefficients, five-year epochs from 2010
to 2030): about −4° in Indiana in 2015, +3.4° in Zürich in 2024, tens of degrees at high latitudes,
to about half a degree away from the poles.
"""

from __future__ import annotations

import datetime

import numpy as np

from quadlib.validation import as_finite_array

__all__ = ["WGS84_A", "WGS84_E2", "geodetic_to_ecef", "geodetic_to_ned", "model_declination_rad"]

WGS84_A = 6378137.0
"""WGS-84 semi-major axis [m]."""
WGS84_E2 = 6.69437999014e-3
"""WGS-84 first eccentricity squared."""


def _lla(name: str, value) -> np.ndarray:
    arr = as_finite_array(name, value)
    if arr.shape[-1:] != (3,) or arr.ndim > 2:
        raise ValueError(f"{name}: expected (latitude [deg], longitude [deg], altitude [m]) as shape (3,) or (N, 3), "
                         f"got shape {arr.shape}")
    if np.any(np.abs(arr[..., 0]) > 90.0) or np.any(np.abs(arr[..., 1]) > 180.0):
        raise ValueError(f"{name}: expected latitudes in [-90, 90] and longitudes in [-180, 180] degrees, got "
                         f"latitude {np.min(arr[..., 0]):g}..{np.max(arr[..., 0]):g}, "
                         f"longitude {np.min(arr[..., 1]):g}..{np.max(arr[..., 1]):g}")
    return arr


def geodetic_to_ecef(lla) -> np.ndarray:
    """ECEF position [m] of ``(latitude [deg], longitude [deg], altitude above the ellipsoid [m])``,
    shape ``(3,)`` or ``(N, 3)``."""
    lla = _lla("lla", lla)
    lat, lon, h = np.radians(lla[..., 0]), np.radians(lla[..., 1]), lla[..., 2]
    n = WGS84_A / np.sqrt(1.0 - WGS84_E2 * np.sin(lat) ** 2)
    return np.stack([(n + h) * np.cos(lat) * np.cos(lon), (n + h) * np.cos(lat) * np.sin(lon),
                     (n * (1.0 - WGS84_E2) + h) * np.sin(lat)], axis=-1)


def geodetic_to_ned(lla, origin) -> np.ndarray:
    """North, east, down [m] of ``lla`` (``(3,)`` or ``(N, 3)``: degrees, degrees, metres) about ``origin``."""
    origin = _lla("origin", origin)
    if origin.shape != (3,):
        raise ValueError(f"origin: expected one point of shape (3,), got shape {origin.shape}")
    lat, lon = np.radians(origin[0]), np.radians(origin[1])
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    c = np.array([[-sl * co, -sl * so, cl], [-so, co, 0.0], [-cl * co, -cl * so, -sl]])
    return (geodetic_to_ecef(lla) - geodetic_to_ecef(origin)) @ c.T


_MODEL_YEARS = (2010, 2030)  # the World Magnetic Model epochs pygeomag holds: 2010, 2015, 2020, 2025


def model_declination_rad(lla, when: datetime.datetime) -> float:
    """The World Magnetic Model's declination [rad], east of true north, at ``lla`` (latitude [deg],
    longitude [deg], height above mean sea level [m], shape (3,)) on the date ``when`` (UTC,
    2010–2029)."""
    from pygeomag import GeoMag, decimal_year_from_date  # only this lookup needs it

    lla = _lla("lla", lla)
    if lla.shape != (3,):
        raise ValueError(f"lla: expected one point of shape (3,), got shape {lla.shape}")
    if not isinstance(when, datetime.datetime):
        raise TypeError(f"when: expected a datetime.datetime (UTC), got {type(when).__name__}")
    if not _MODEL_YEARS[0] <= when.year < _MODEL_YEARS[1]:
        raise ValueError(f"when: expected a date in {_MODEL_YEARS[0]}–{_MODEL_YEARS[1] - 1} (the World Magnetic "
                         f"Model's epochs), got {when.date().isoformat()}")
    result = GeoMag(base_year=when.year).calculate(glat=float(lla[0]), glon=float(lla[1]), alt=float(lla[2]) / 1000.0,
                                                   time=decimal_year_from_date(when))
    return float(np.radians(result.d))
