"""The IMU log container."""

import numpy as np
import pytest

from quadlib.imu import ImuLog, ImuNoise, saturated_step_variance, untrusted_gyro_noise


def test_a_log_holds_read_only_streams_and_slices():
    t = np.arange(5) * 0.01
    log = ImuLog(t, np.zeros((5, 3)), np.tile([0, 0, -9.8], (5, 1)), np.full((5, 3), np.nan), np.arange(5.0))
    assert len(log) == 5 and np.allclose(log.dt, 0.01)
    with pytest.raises(ValueError, match="read-only"):
        log.gyro[0, 0] = 1.0
    part = log.slice(1, 3)
    assert len(part) == 2 and part.t[0] == 0.01 and part.airspeed.tolist() == [1.0, 2.0]
    assert ImuLog(t, np.zeros((5, 3)), np.zeros((5, 3))).mag is None


def test_bad_logs_are_refused_with_the_field_named():
    t = np.arange(3.0)
    with pytest.raises(ValueError, match=r"ImuLog.gyro: expected shape \(3, 3\), got \(3, 2\)"):
        ImuLog(t, np.zeros((3, 2)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"ImuLog.accel: expected finite values or NaN for missing, got \d+ inf"):
        ImuLog(t, np.zeros((3, 3)), np.full((3, 3), np.inf))
    with pytest.raises(ValueError, match="ImuLog.t: expected strictly increasing times"):
        ImuLog([0.0, 0.0, 1.0], np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"ImuLog.airspeed: expected shape \(3,\), got \(3, 1\)"):
        ImuLog(t, np.zeros((3, 3)), np.zeros((3, 3)), airspeed=np.zeros((3, 1)))


def test_the_log_freezes_its_own_copy_not_the_callers_arrays():
    t, gyro = np.arange(3.0), np.zeros((3, 3))
    log = ImuLog(t, gyro, np.zeros((3, 3)))
    gyro[0, 0] = 1.0  # the caller's array stays writable
    t[0] = -1.0
    assert log.gyro[0, 0] == 0.0 and log.t[0] == 0.0


def test_a_saturated_gyro_sample_adds_the_variance_of_one_more_full_scale_step():
    assert saturated_step_variance([0.0, 34.0, 0.0], 0.004, 35.0) is None  # within range
    assert saturated_step_variance([0.0, -35.0, 0.0], 0.004, 35.0) == pytest.approx((35.0 * 0.004) ** 2)
    assert saturated_step_variance([0.0, 1e3, 0.0], 0.004, None) is None  # no range: never saturated
    noise = untrusted_gyro_noise(35.0, [1.0, 1.0, 1.0, 0.0])
    np.testing.assert_allclose(noise(np.array([35.0, 0.0, 0.0]), 0.01), np.diag([0.35**2] * 3 + [0.0]))
    assert noise(np.zeros(3), 0.01) is None and untrusted_gyro_noise(None, [1.0]) is None
    with pytest.raises(ValueError, match=r"ImuNoise.gyro_range_rad_s: expected a finite number > 0 or None, "
                                         r"got -1.0"):
        ImuNoise(gyro_range_rad_s=-1.0)


def test_the_simulated_gyro_clips_at_its_full_scale():
    from quadlib.attitude.tumble import random_rotation, with_spin
    from quadlib.sim.imu import imu_samples

    motion = with_spin(random_rotation(2.0, 100.0, np.random.default_rng(0)), 0.5, 0.5, 40.0)
    log = imu_samples(motion, ImuNoise(gyro_range_rad_s=30.0), np.random.default_rng(1))
    assert np.abs(log.gyro).max() == 30.0 and (log.gyro[:, 0] == 30.0).sum() >= 50
    assert np.abs(imu_samples(motion, ImuNoise(), np.random.default_rng(1)).gyro).max() > 39.0
