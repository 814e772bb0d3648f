"""Geodetic coordinates to local NED, against WGS-84 textbook values."""

import numpy as np
import pytest

from quadlib.geometry import geodetic_to_ecef, geodetic_to_ned


def test_ecef_of_known_points():
    np.testing.assert_allclose(geodetic_to_ecef([0.0, 0.0, 0.0]), [6378137.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(geodetic_to_ecef([90.0, 0.0, 0.0]), [0.0, 0.0, 6356752.314], atol=1e-3)  # polar radius
    np.testing.assert_allclose(geodetic_to_ecef([0.0, 90.0, 100.0]), [0.0, 6378237.0, 0.0], atol=1e-6)


def test_ned_offsets_near_an_origin():
    origin = np.array([40.466, -86.97, 200.0])
    ned = geodetic_to_ned(origin + [[1e-4, 0.0, 0.0], [0.0, 1e-4, 0.0], [0.0, 0.0, 3.0]], origin)
    lat = np.radians(origin[0])
    e2, a = 6.69437999014e-3, 6378137.0
    r_m = a * (1 - e2) / (1 - e2 * np.sin(lat) ** 2) ** 1.5  # meridian radius of curvature
    r_n = a / np.sqrt(1 - e2 * np.sin(lat) ** 2)
    step = np.radians(1e-4)
    expected = [[step * (r_m + 200.0), 0.0, 0.0], [0.0, step * (r_n + 200.0) * np.cos(lat), 0.0], [0.0, 0.0, -3.0]]
    np.testing.assert_allclose(ned, expected, atol=2e-4)  # 11 m and 8.5 m: flat earth to a fraction of a mm
    assert np.array_equal(geodetic_to_ned(origin, origin), [0.0, 0.0, 0.0])


def test_bad_coordinates_are_named():
    with pytest.raises(ValueError, match=r"origin: expected one point of shape \(3,\)"):
        geodetic_to_ned([0.0, 0.0, 0.0], [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="lla: expected latitudes in"):
        geodetic_to_ned([95.0, 0.0, 0.0], [0.0, 0.0, 0.0])
