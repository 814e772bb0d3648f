"""The orientation MEKF: a slice of a real BROAD trial, a known gyro bias, a magnet, and its inputs."""

import numpy as np
import pytest

from quadlib.analysis.metrics import attitude_error, broad_errors
from quadlib.attitude.checks import SensorChecks
from quadlib.attitude.orientation import OrientationParams, estimate_orientation
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.data import load_broad_trial
from quadlib.imu import ImuLog, ImuNoise
from quadlib.sim.imu import imu_samples


def test_a_slice_of_a_real_trial_is_tracked_to_a_few_degrees():
    trial = load_broad_trial("02_undisturbed_slow_rotation_B")
    n = 3000  # the first 10.5 s: rest, then slow rotations
    run = estimate_orientation(trial.log.slice(0, n))
    errors = broad_errors(run.x[:, :4], trial.q_nb[:n])  # every sample of the slice, at rest or moving
    assert errors["total_deg"] < 3.0 and errors["inclination_deg"] < 2.0


FIELD = earth_field_ned(50.0, np.radians(65.0))
MOTION = random_rotation(40.0, 100.0, np.random.default_rng(3), rms_rate_rad_s=0.5)


def test_a_constant_gyro_bias_is_estimated():
    bias = np.array([0.02, -0.015, 0.01])
    noise = ImuNoise(gyro_sigma_rad_s=0.002, gyro_bias_rad_s=tuple(bias), accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(4), field_n=FIELD)
    run = estimate_orientation(log)
    np.testing.assert_allclose(run.x[-1, 4:], bias, atol=2e-3)
    assert np.degrees(attitude_error(run.x[:, :4], MOTION.q_nb))[MOTION.t > 10].max() < 2.0


def test_a_magnet_near_the_sensor_does_not_turn_the_heading():
    noise = ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(5), field_n=FIELD)
    mag = np.array(log.mag)
    near = (log.t > 15) & (log.t < 25)
    mag[near] += [60.0, 0.0, 0.0]  # a magnet fixed to the sensor, stronger than the Earth's field
    run = estimate_orientation(ImuLog(log.t, log.gyro, log.accel, mag))
    err = np.degrees(attitude_error(run.x[:, :4], MOTION.q_nb))
    assert err[near].max() < 3.0 and err[MOTION.t > 30].max() < 2.0
    trusting = OrientationParams(gate_probability=None, checks=SensorChecks(None, None, None, None))
    believed = estimate_orientation(ImuLog(log.t, log.gyro, log.accel, mag), trusting)
    assert np.degrees(attitude_error(believed.x[:, :4], MOTION.q_nb))[near].max() > 10.0  # the checks matter


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="log: expected an ImuLog, got tuple"):
        estimate_orientation((np.zeros(3), np.zeros((3, 3))))


def test_the_heading_jacobian_is_exact_in_error_coordinates():
    from quadlib.attitude.bias_model import attitude_bias_model
    from quadlib.attitude.orientation import heading_sensor
    from quadlib.geometry.quaternion import quat_normalize

    model, sensor, rng = attitude_bias_model(0.005, 1e-4), heading_sensor(0.1), np.random.default_rng(1)
    for _ in range(20):
        x = np.r_[quat_normalize(rng.normal(size=4)), rng.normal(size=3) * 0.01]
        m_b, eps = rng.normal(size=3) * 30, 1e-6
        analytic = sensor.H(x, m_b) @ model.add_jacobian(x)
        differences = [sensor.residual(sensor.h(model.state_add(x, eps * e), m_b),
                                       sensor.h(model.state_add(x, -eps * e), m_b))[0] / (2 * eps) for e in np.eye(6)]
        np.testing.assert_allclose(analytic[0], differences, rtol=1e-6, atol=1e-9)
