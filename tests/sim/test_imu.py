"""The one IMU simulator: noise statistics, bias and random walk, magnetometer, NaN rows."""

import numpy as np
import pytest

from quadlib.constants import earth_field_ned
from quadlib.geometry.quaternion import quat_from_euler, quat_to_dcm
from quadlib.imu import ImuNoise
from quadlib.sim.imu import BodyMotion, imu_samples, specific_force_at_rest

N = 20000
Q = quat_from_euler(np.full(N, 0.3), np.full(N, -0.2), np.full(N, 1.0))
STILL = BodyMotion(t=np.arange(N) * 0.01, q_nb=Q, omega_b=np.zeros((N, 3)), f_b=specific_force_at_rest(Q))


def test_specific_force_at_rest_is_minus_gravity_in_the_body_frame():
    np.testing.assert_allclose(quat_to_dcm(Q[0]) @ STILL.f_b[0], [0.0, 0.0, -9.80665], atol=1e-12)


def test_noise_bias_and_field_have_the_stated_statistics():
    noise = ImuNoise(gyro_sigma_rad_s=0.01, gyro_bias_rad_s=(0.1, -0.2, 0.3), accel_sigma_m_s2=(0.1, 0.2, 0.3),
                     mag_sigma=0.5)
    field = earth_field_ned(50.0, 1.1)
    log = imu_samples(STILL, noise, np.random.default_rng(1), field_n=field)
    tol = 4 / np.sqrt(N)  # four standard errors, relative
    np.testing.assert_allclose(log.gyro.mean(axis=0), [0.1, -0.2, 0.3], atol=4 * 0.01 / np.sqrt(N))
    np.testing.assert_allclose(log.gyro.std(axis=0), 0.01, rtol=tol * 2)
    np.testing.assert_allclose(log.accel.std(axis=0), [0.1, 0.2, 0.3], rtol=tol * 2)
    np.testing.assert_allclose(log.mag.mean(axis=0), quat_to_dcm(Q[0]).T @ field, atol=4 * 0.5 / np.sqrt(N))


def test_the_bias_walks_with_the_stated_rate_and_missing_samples_are_nan_rows():
    noise = ImuNoise(gyro_sigma_rad_s=1e-9, gyro_bias_walk_rad_s_sqrt_s=0.002)
    walks = np.array([imu_samples(STILL, noise, np.random.default_rng(s)).gyro[-1] for s in range(200)])
    duration = STILL.t[-1] - STILL.t[0] + 0.01  # N steps of 0.01 s
    assert np.std(walks) == pytest.approx(0.002 * np.sqrt(duration), rel=0.15)
    log = imu_samples(STILL, ImuNoise(), np.random.default_rng(2), field_n=[0.2, 0, 0.4], mag_every=4, accel_every=2)
    assert np.isnan(log.mag).any(axis=1).sum() == N - N // 4 and np.isnan(log.accel[1::2]).all()
    assert not np.isnan(log.gyro).any()


def test_a_seed_gives_the_same_log_and_bad_arguments_are_named():
    a, b = (imu_samples(STILL, ImuNoise(), np.random.default_rng(5)) for _ in range(2))
    np.testing.assert_array_equal(a.gyro, b.gyro)
    with pytest.raises(TypeError, match="noise: expected an ImuNoise, got dict"):
        imu_samples(STILL, {}, np.random.default_rng(0))
    with pytest.raises(ValueError, match="mag_every: expected an int >= 1, got 0"):
        imu_samples(STILL, ImuNoise(), np.random.default_rng(0), mag_every=0)
