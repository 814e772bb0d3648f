"""filterpy's attributes are the filter's truth: ``Q``, ``x``, ``P`` and ``model`` set on a built filter
take effect at the next step, on a regular clock and a jittery one and on both engines; ``R``, which a
quadlib filter takes from each sensor, is refused with a message that says where it lives."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib import LinearKF, Measurements, ModelEKF, ModelUKF, run_filter
from quadlib.attitude.bias_model import attitude_bias_model
from quadlib.attitude.orientation import gravity_sensor
from quadlib.engine import Kernel
from quadlib.geometry.quaternion import quat_from_rotvec, quat_multiply
from tests.engine.test_build import CART, RANGE, _log, cart_Q

CLOCKS = {"regular clock": 0.0, "jittery clock": 0.2}
FILTERS = {"EKF": ModelEKF, "UKF": ModelUKF}
ENGINES = ("compiled", "readable")
X0, P0 = np.array([-4.0, 0.5]), np.diag([1.0, 1.0])


def _run(filt, clock: str, engine: str):
    t, u, z = _log(CLOCKS[clock])
    return run_filter(filt, t, u, [Measurements(RANGE, t, z)], engine=engine)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("clock", list(CLOCKS))
@pytest.mark.parametrize("kind", list(FILTERS))
def test_an_assigned_Q_holds_for_every_later_step(kind, clock, engine):
    make = FILTERS[kind]
    filt = make(CART, X0, P0, 0.02)
    Q = 100 * filt.Q
    filt.Q = Q
    np.testing.assert_array_equal(filt.Q, Q)
    got = _run(filt, clock, engine)
    assert got.engine == engine
    fixed = make(replace(CART, Q=lambda dt: Q), X0, P0, 0.02)  # the same noise, whatever the step
    expected = _run(fixed, clock, "readable")
    np.testing.assert_allclose(got.x, expected.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(got.P, expected.P, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(filt.Q, Q)  # still the assigned one after the run
    assert np.abs(got.x - _run(make(CART, X0, P0, 0.02), clock, engine).x).max() > 1e-3  # and it mattered


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("clock", list(CLOCKS))
@pytest.mark.parametrize("kind", list(FILTERS))
def test_an_assigned_model_takes_effect_at_the_next_step(kind, clock, engine):
    make = FILTERS[kind]
    windy = replace(CART, Q=Kernel("Q", cart_Q, [3.0]))
    filt = make(CART, X0, P0, 0.02)
    filt.Q = 7 * filt.Q  # dropped with the old model
    filt.model = windy
    got = _run(filt, clock, engine)
    expected = _run(make(windy, X0, P0, 0.02), clock, "readable")
    np.testing.assert_allclose(got.x, expected.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(got.P, expected.P, rtol=0, atol=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("kind", list(FILTERS))
def test_assigned_x_and_P_are_where_the_next_step_starts(kind, engine):
    make = FILTERS[kind]
    filt = make(CART, X0, P0, 0.02)
    filt.x = np.array([-3.0, 0.2]) if kind == "UKF" else np.array([[-3.0], [0.2]])  # filterpy's own shapes
    filt.P = np.diag([0.5, 2.0])
    got = _run(filt, "jittery clock", engine)
    expected = _run(make(CART, [-3.0, 0.2], np.diag([0.5, 2.0]), 0.02), "jittery clock", "readable")
    np.testing.assert_allclose(got.x, expected.x, rtol=0, atol=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
def test_an_assigned_error_state_is_folded_in_before_the_next_step(engine):
    model = attitude_bias_model(0.005, 1e-4)
    q0, delta = np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.1, -0.05, 0.02, 0.0, 0.0, 0.0])
    t = np.arange(200) * 0.01
    gyro = np.tile([0.1, 0.0, -0.1], (t.size, 1))
    accel = np.tile([0.0, 0.0, -9.81], (t.size, 1))
    filt = ModelEKF(model, np.r_[q0, 0.0, 0.0, 0.0], np.eye(6) * 0.01, 0.01)
    filt.x = delta.reshape(-1, 1)  # the error, which the next step folds into the nominal state
    got = run_filter(filt, t, gyro, [Measurements(gravity_sensor(0.2), t, accel)], engine=engine)
    start = np.r_[quat_multiply(q0, quat_from_rotvec(delta[:3])), 0.0, 0.0, 0.0]
    expected = run_filter(ModelEKF(model, start, np.eye(6) * 0.01, 0.01), t, gyro,
                          [Measurements(gravity_sensor(0.2), t, accel)], engine="readable")
    np.testing.assert_allclose(got.x, expected.x, rtol=0, atol=1e-9)


@pytest.mark.parametrize("kind", list(FILTERS))
def test_R_is_refused_with_where_it_lives(kind):
    filt = FILTERS[kind](CART, X0, P0, 0.02)
    with pytest.raises(AttributeError, match=r"R: a quadlib filter takes each sample's noise from its sensor.*"
                                             r"dataclasses.replace\(sensor, R=...\)"):
        filt.R = np.eye(1)
    filt.update_sensor(RANGE, [4.5])
    np.testing.assert_array_equal(filt.R, RANGE.R)  # reading it: the last update's


def test_a_model_of_another_shape_is_refused():
    filt = ModelEKF(CART, X0, P0, 0.02)
    with pytest.raises(ValueError, match="model: expected a model of the filter's shape"):
        filt.model = attitude_bias_model(0.005, 1e-4)
    with pytest.raises(TypeError, match="model: expected a quadlib Model, got str"):
        filt.model = "cart"
    with pytest.raises(ValueError, match="model: 'cart' has no Jacobian G; ModelEKF needs one"):
        filt.model = replace(CART, G=None)


def test_linear_kf_honours_Q_and_checks_a_new_model():
    linear = replace(CART, g=lambda x, u, dt: np.array([x[0] + dt * x[1], x[1] + dt * u[0]]),
                     B=lambda x, u, dt: np.array([[0.0], [dt]]))
    filt = LinearKF(linear, X0, P0, 0.02)
    filt.Q = np.eye(2)
    filt.predict([0.0], 0.02)
    F = np.array([[1.0, 0.02], [0.0, 1.0]])
    np.testing.assert_allclose(filt.P, F @ P0 @ F.T + np.eye(2), rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="is not linear"):
        filt.model = replace(linear, g=lambda x, u, dt: x**2)
