import numpy as np
import pytest

from quadlib.constants import GRAVITY_N
from quadlib.geometry.quaternion import integrate_body_rate, quat_canonical, quat_to_dcm
from quadlib.geometry.rotations import mag_heading, wrap_angle
from quadlib.quad.flight import (
    SensorNoise3D,
    baro_samples,
    figure_eight,
    flight_from_path,
    gps_samples,
    mag_field_samples,
    mag_yaw_samples,
    square_course,
)
from quadlib.sim.imu import imu_samples


def test_hovering_accelerometer_reads_minus_g_on_body_z():
    t = np.arange(0.0, 2.0, 0.002)
    zeros = np.zeros((t.size, 3))
    hover = flight_from_path(t, zeros + [0.0, 0.0, -3.0], zeros, zeros, np.full(t.size, 0.7))
    np.testing.assert_allclose(hover.f_b, np.tile([0.0, 0.0, -9.80665], (t.size, 1)), atol=1e-12)
    noise = SensorNoise3D()
    imu = imu_samples(hover, noise, np.random.default_rng(0))
    four_sigma_of_mean = 4.0 / np.sqrt(t.size)  # times each sensor's σ per sample
    accel_bound = four_sigma_of_mean * np.asarray(noise.accel_sigma_m_s2)
    assert np.all(np.abs(imu.accel.mean(axis=0) - [0.0, 0.0, -9.80665]) < accel_bound)
    assert np.all(np.abs(imu.gyro.mean(axis=0)) < four_sigma_of_mean * noise.gyro_sigma_rad_s)
    np.testing.assert_allclose(imu.accel.std(axis=0), noise.accel_sigma_m_s2, rtol=0.1)
    np.testing.assert_allclose(hover.euler[:, 2], 0.7)


@pytest.mark.parametrize("flight", [square_course(leg_s=3.0, turn_s=1.0), figure_eight(duration_s=10.0)],
                         ids=["square", "figure-eight"])
def test_truth_is_self_consistent(flight):
    R = quat_to_dcm(flight.q_nb)
    # specific force + gravity is the path's acceleration, and a quadrotor's thrust is along body z
    np.testing.assert_allclose(np.einsum("nij,nj->ni", R, flight.f_b) + GRAVITY_N, flight.acc, atol=1e-9)
    np.testing.assert_allclose(flight.f_b[:, :2], 0.0, atol=1e-9)
    # integrating the body rates reproduces the attitude
    q = flight.q_nb[0]
    for k in range(flight.t.size - 1):
        q = integrate_body_rate(q, flight.omega_b[k], flight.dt)
    np.testing.assert_allclose(quat_canonical(q), quat_canonical(flight.q_nb[-1]), atol=1e-8)
    # velocity and acceleration are the derivatives of position
    np.testing.assert_allclose(np.gradient(flight.pos, flight.dt, axis=0)[1:-1], flight.vel[1:-1], atol=1e-3)
    np.testing.assert_allclose(np.gradient(flight.vel, flight.dt, axis=0)[1:-1], flight.acc[1:-1], atol=0.03)


def test_square_course_returns_home_and_its_yaw_crosses_pi():
    sq = square_course()
    np.testing.assert_allclose(sq.pos[-1], sq.pos[0], atol=1e-12)
    jumps = np.abs(np.diff(sq.euler[:, 2])) > np.pi
    assert jumps.sum() == 1  # wrapped once, from +π to −π
    assert np.all(np.abs(wrap_angle(np.diff(sq.euler[:, 2]))) < 0.01)  # but continuous as an angle
    peak_tilt = np.degrees(np.arccos(np.clip(quat_to_dcm(sq.q_nb)[:, 2, 2], -1, 1)).max())
    assert 10.0 < peak_tilt < 16.0  # 2.3 m/s² peak acceleration


def test_sensor_rates_and_noise():
    fl = figure_eight(duration_s=20.0)
    noise, rng = SensorNoise3D(), np.random.default_rng(3)
    gps = gps_samples(fl, noise, rng)
    assert gps.z.shape == (201, 6) and np.allclose(np.diff(gps.t), 0.1)
    k = np.searchsorted(fl.t, gps.t)
    err = gps.z - np.hstack([fl.pos[k], fl.vel[k]])
    np.testing.assert_allclose(err.std(axis=0), [0.7, 0.7, 2.0, 0.1, 0.1, 0.3], rtol=0.15)
    mag = mag_yaw_samples(fl, noise, rng)
    assert mag.z.shape == (2001, 1)
    yaw_err = wrap_angle(mag.z[:, 0] - fl.euler[np.searchsorted(fl.t, mag.t), 2])
    assert 0.09 < yaw_err.std() < 0.11
    field = mag_field_samples(fl, noise, rng)
    km = np.searchsorted(fl.t, field.t)
    heading = mag_heading(field.z, fl.euler[km, 0], fl.euler[km, 1])
    assert np.abs(wrap_angle(heading - fl.euler[km, 2])).max() < 0.15  # 0.01 G on a 0.25 G horizontal field
    baro = baro_samples(fl, noise, rng)
    assert baro.z.shape == (501, 1) and abs(baro.z.mean() - 3.0) < 0.1
    with pytest.raises(ValueError, match="rate_hz: expected at most the flight's rate 500 Hz, got 1000"):
        gps_samples(fl, SensorNoise3D(gps_rate_hz=1000.0), rng)


def test_gyro_bias_and_random_walk():
    fl = figure_eight(duration_s=10.0)
    noise = SensorNoise3D(gyro_sigma_rad_s=0.0, gyro_bias_rad_s=(0.01, -0.02, 0.03), gyro_bias_walk_rad_s_sqrt_s=0.001)
    imu = imu_samples(fl, noise, np.random.default_rng(1))
    bias = imu.gyro - fl.omega_b
    np.testing.assert_allclose(bias[0], [0.01, -0.02, 0.03], atol=1e-4)
    walk = bias[-1] - bias[0]
    assert np.all(np.abs(walk) < 5 * 0.001 * np.sqrt(10.0)) and np.any(walk != 0)
