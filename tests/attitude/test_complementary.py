import numpy as np
import pytest

from quadlib.attitude.complementary import (
    blend_weight,
    euler_rate_complementary,
    linear_complementary,
    nonlinear_complementary,
)
from quadlib.geometry.rotations import accel_tilt, euler_rate_matrix
from quadlib.quad.flight import SensorNoise3D, figure_eight, square_course
from quadlib.sim.imu import imu_samples

SQUARE = square_course(leg_s=3.0, turn_s=1.0, rate_hz=250.0)


def test_linear_filter_is_eqs_41_42_written_as_a_loop():
    imu = imu_samples(SQUARE, SensorNoise3D(), np.random.default_rng(2))
    dt, tau = SQUARE.dt, 0.5
    a = tau / (tau + dt)
    tilt = np.column_stack(accel_tilt(imu.accel))
    expected = np.empty_like(tilt)
    expected[0] = tilt[0]
    for k in range(1, len(tilt)):
        expected[k] = a * (expected[k - 1] + dt * imu.gyro[k - 1, :2]) + (1 - a) * tilt[k]
    np.testing.assert_allclose(linear_complementary(dt, imu.gyro, imu.accel, tau), expected, atol=1e-12)


def test_with_a_perfect_gyro_and_no_accelerometer_weight_the_filters_integrate():
    flight = figure_eight(duration_s=8.0, rate_hz=250.0)  # tilted and turning at once
    truth, tau = flight.euler[:, :2], 1e12  # a = 1: gyro only
    args = (flight.dt, flight.omega_b, flight.f_b, tau)
    nl = nonlinear_complementary(*args, yaw=flight.euler[:, 2], initial=truth[0])
    er = euler_rate_complementary(*args, initial=truth[0])
    lin = linear_complementary(*args, initial=truth[0])
    assert np.abs(nl - truth).max() < 1e-6  # exact quaternion integration
    assert np.abs(er - truth).max() < 2e-3  # first-order Euler-rate integration
    assert np.abs(lin - truth).max() > 10 * np.abs(er - truth).max()  # p, q are not Euler rates in a banked turn


def test_complementary_beats_gyro_only_and_accelerometer_only_in_slow_flight():
    flight = square_course(leg_s=8.0, turn_s=2.0, rate_hz=250.0)
    imu = imu_samples(flight, SensorNoise3D(), np.random.default_rng(4))
    truth = flight.euler[:, :2]

    def rms(est):
        return np.sqrt(np.mean((est - truth) ** 2))

    accel_only = rms(np.column_stack(accel_tilt(imu.accel)))
    gyro_only = rms(euler_rate_complementary(flight.dt, imu.gyro, imu.accel, 1e12))
    blended = rms(euler_rate_complementary(flight.dt, imu.gyro, imu.accel, 1.0))
    assert blended < 0.75 * min(accel_only, gyro_only)


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match=r"gyro, accel: expected two \(N, 3\) arrays, got \(5, 3\) and \(4, 3\)"):
        linear_complementary(0.01, np.zeros((5, 3)), np.zeros((4, 3)), 1.0)
    with pytest.raises(ValueError, match="tau"):
        blend_weight(-1.0, 0.01)
    with pytest.raises(ValueError, match=r"yaw: expected shape \(5,\), got \(4,\)"):
        nonlinear_complementary(0.01, np.zeros((5, 3)), np.tile([0, 0, -9.8], (5, 1)), 1.0, yaw=np.zeros(4))


def test_free_fall_and_missing_samples_leave_the_gyro_alone():
    dt, n = 0.01, 300
    gyro = np.zeros((n, 3))
    gyro[:, 0] = 0.1  # rolling at 0.1 rad/s
    accel = np.tile([0.0, 0.0, -9.80665], (n, 1))
    accel[100:200] = [0.0, 0.0, 0.0]  # a second of free fall
    accel[250] = np.nan
    for filt in (linear_complementary, euler_rate_complementary):
        out = filt(dt, gyro, accel, 1.0)
        np.testing.assert_allclose(np.diff(out[100:200, 0]), 0.1 * dt, rtol=1e-12)  # pure gyro in free fall
        assert np.isfinite(out).all()
    with pytest.raises(ValueError, match="accel: expected a first sample that gives a tilt"):
        linear_complementary(dt, gyro, np.zeros((n, 3)), 1.0)


def _euler_rate_reference(dt, gyro, accel, tau, initial):
    """The filter written out with the project's Euler-rate matrix and tilt, step by step."""
    tilt = np.column_stack(accel_tilt(accel))
    a = tau / (tau + dt)
    out = [tilt[0] if initial is None else np.asarray(initial, dtype=float)]
    for k in range(1, len(tilt)):
        rates = euler_rate_matrix(out[-1][0], out[-1][1])[:2] @ gyro[k - 1]
        predicted = out[-1] + dt * rates
        out.append(predicted if np.isnan(tilt[k]).any() else a * predicted + (1.0 - a) * tilt[k])
    return np.array(out)


def test_the_compiled_euler_rate_loop_follows_the_euler_rate_equations():
    """simulate_run3d and the fixed-wing comparison use it; chapters store its every bit."""
    rng = np.random.default_rng(6)
    n = 3000
    gyro = rng.normal(0.0, 1.5, (n, 3))
    accel = np.tile([0.0, 0.0, -9.80665], (n, 1)) + rng.normal(0.0, 2.0, (n, 3))
    accel[500:600] = 0.0  # free fall
    accel[rng.random(n) < 0.05] = np.nan  # dropouts
    for tau, initial in ((1.0, None), (0.2, [0.3, -0.2]), (5.0, None)):
        np.testing.assert_allclose(euler_rate_complementary(0.004, gyro, accel, tau, initial),
                                   _euler_rate_reference(0.004, gyro, accel, tau, initial), rtol=0, atol=1e-9)
