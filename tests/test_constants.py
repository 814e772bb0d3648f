"""g0, gravity in NED and the Earth's field."""

import numpy as np
import pytest

from quadlib.constants import G0, GRAVITY_N, earth_field_ned


def test_gravity_points_down_in_ned_and_cannot_be_changed():
    np.testing.assert_array_equal(GRAVITY_N, [0.0, 0.0, G0])
    with pytest.raises(ValueError, match="read-only"):
        GRAVITY_N[2] = 9.81


def test_earth_field_has_its_strength_dip_and_declination():
    m = earth_field_ned(50.0, np.radians(65.0), np.radians(3.0))
    assert np.linalg.norm(m) == pytest.approx(50.0)
    assert np.degrees(np.arcsin(m[2] / 50.0)) == pytest.approx(65.0)  # down, below the horizon
    assert np.degrees(np.arctan2(m[1], m[0])) == pytest.approx(3.0)  # east of north
    np.testing.assert_allclose(earth_field_ned(1.0, 0.0), [1.0, 0.0, 0.0])
    with pytest.raises(TypeError, match=r"inclination_rad: expected a real number, got \[0.1, 0.2\]"):
        earth_field_ned(1.0, [0.1, 0.2])
