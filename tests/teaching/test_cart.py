"""The cart of chapters 05–06: the 1D quadrotor's double integrator under the cart's names."""

import numpy as np
import pytest

from quadlib.quad import quad1d_model
from quadlib.teaching import cart_model, cart_position_sensor, cart_speed_sensor


def test_the_cart_coasts_and_accelerates_as_a_double_integrator():
    model = cart_model(0.5)
    assert model.state_names == ("v [m/s]", "p [m]") and model.input_names == ("a [m/s^2]",)
    np.testing.assert_allclose(model.g(np.array([2.0, 1.0]), np.array([0.0]), 0.5), [2.0, 2.0])  # coasting
    np.testing.assert_allclose(model.g(np.array([2.0, 1.0]), np.array([1.0]), 0.5), [2.5, 2.0])
    np.testing.assert_allclose(model.G(None, None, 0.1), [[1.0, 0.0], [0.1, 1.0]])
    gamma = np.array([0.1, 0.005])
    np.testing.assert_allclose(model.Q(0.1), 0.25 * np.outer(gamma, gamma))
    np.testing.assert_allclose(model.Q(0.1), quad1d_model(0.5).Q(0.1))


def test_the_sensors_see_position_or_speed():
    x = np.array([2.0, 7.0])
    position, speed = cart_position_sensor(0.2, rate_hz=5.0), cart_speed_sensor(0.1)
    assert position.h(x).tolist() == [7.0] and speed.h(x).tolist() == [2.0]
    np.testing.assert_allclose(position.H(x), [[0.0, 1.0]])
    np.testing.assert_allclose(speed.H(x), [[1.0, 0.0]])
    np.testing.assert_allclose([position.R[0, 0], speed.R[0, 0]], [0.04, 0.01])
    assert position.rate_hz == 5.0 and position.name == "position" and speed.name == "speed"
    with pytest.raises(ValueError, match="sigma_m_s"):
        cart_speed_sensor(-1.0)
