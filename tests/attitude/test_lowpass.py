"""The compiled low-passes of rest detection and of the accelerometer equal their uncompiled source."""

import numpy as np

from quadlib.attitude.lowpass import inertial_lowpass, rest_mask
from quadlib.attitude.orientation import OrientationParams
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.imu import ImuNoise
from quadlib.kernels.lowpass import calm_samples, inertial_lowpass_pass
from quadlib.sim.imu import imu_samples


def test_the_compiled_lowpasses_equal_their_interpreted_source():
    motion = random_rotation(10.0, 100.0, np.random.default_rng(5), rms_rate_rad_s=1.0)
    log = imu_samples(motion, ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3),
                      np.random.default_rng(6), field_n=earth_field_ned(50.0, np.radians(65.0)))
    accel = log.accel.copy()
    accel[np.random.default_rng(7).random(len(log)) < 0.05] = np.nan
    params = OrientationParams()
    gyro = np.ascontiguousarray(log.gyro)
    usable = ~np.isnan(accel).any(axis=1)
    lost = np.zeros(len(log), bool)
    lost[[40, 41, 900]] = True  # two frames lost: the average starts afresh after each
    for backward in (False, True):
        for second_order in (False, True):
            np.testing.assert_array_equal(
                inertial_lowpass_pass(log.t, gyro, accel, usable, lost, 1.0, backward, second_order),
                inertial_lowpass_pass.py_func(log.t, gyro, accel, usable, lost, 1.0, backward, second_order))
    args = (log.t, log.gyro, accel, params.rest_gyro_rad_s, params.rest_accel_m_s2, 0.5)
    assert np.array_equal(calm_samples(*args), calm_samples.py_func(*args))
    assert rest_mask(log, 0.1, 0.5, 0.5).dtype == bool
    assert inertial_lowpass(log, 3.0).shape == accel.shape
