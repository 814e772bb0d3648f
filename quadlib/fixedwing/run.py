"""Run the three fixed-wing attitude estimators of chapter 12 on one set of samples.

* ``"EKF"`` — Salmony's EKF (:mod:`quadlib.fixedwing.ekf`);
* ``"ES-UKF"`` — the error-state UKF (:mod:`quadlib.fixedwing.ukf`);
* ``"complementary"`` — chapter 7's Euler-rate complementary filter for roll and pitch, and the
  tilt-compensated magnetometer heading for yaw: no bias estimate, no airspeed.

Each returns roll, pitch, yaw ``(N, 3)`` [rad] and, for the Kalman filters, the bias ``(N, 3)``.
"""

from __future__ import annotations

import numpy as np

from quadlib.attitude.complementary import euler_rate_complementary
from quadlib.filters import ModelEKF
from quadlib.fixedwing.ekf import fixedwing_mag_sensor, fixedwing_model, initial_state, run_fixedwing_ekf
from quadlib.fixedwing.sim import FixedWingNoise, FixedWingSamples
from quadlib.fixedwing.ukf import ErrorStateUKF
from quadlib.geometry.quaternion import quat_to_euler
from quadlib.geometry.rotations import mag_heading

__all__ = ["ESTIMATORS", "run_estimator"]

ESTIMATORS = ("EKF", "ES-UKF", "complementary")


def run_estimator(name: str, samples: FixedWingSamples, noise: FixedWingNoise, dt: float, n_still: int,
                  inclination_rad: float | None = None, prefilter_hz: float | None = None):
    """``(euler (N, 3), bias (N, 3) or None)`` of estimator ``name`` (one of :data:`ESTIMATORS`).

    ``inclination_rad`` is the field dip the magnetometer model assumes (default: the true one);
    0 is the document's horizontal-field model.
    """
    incl = noise.inclination_rad if inclination_rad is None else float(inclination_rad)
    mag_sigma = max(noise.mag_sigma, 1e-6)
    if name == "EKF":
        x0 = initial_state(samples, n_still)
        ekf = ModelEKF(fixedwing_model(noise.gyro_sigma_rad_s, max(noise.gyro_bias_walk_rad_s_sqrt_s, 1e-6)), x0,
                       np.diag([0.01] * 4 + [0.02**2] * 3), dt)
        x, _ = run_fixedwing_ekf(ekf, dt, samples, fixedwing_mag_sensor(noise.declination_rad, mag_sigma, incl),
                                 noise.accel_sigma_m_s2, prefilter_hz=prefilter_hz)
        return np.column_stack(quat_to_euler(x[:, :4])), x[:, 4:]
    if name == "ES-UKF":
        x0 = initial_state(samples, n_still)
        ukf = ErrorStateUKF(x0[:4], x0[4:], 0.05, 0.02, noise.gyro_sigma_rad_s,
                            max(noise.gyro_bias_walk_rad_s_sqrt_s, 1e-6), dt)
        x = np.empty((len(samples.gyro), 7))
        for k in range(len(x)):
            if k:
                ukf.predict(samples.gyro[k - 1], dt)
            va = None if np.isnan(samples.airspeed[k]) else samples.airspeed[k]
            mag = None if np.isnan(samples.mag[k]).any() else samples.mag[k]
            ukf.update(samples.accel[k], mag, omega=samples.gyro[k], airspeed_m_s=va,
                       accel_sigma=noise.accel_sigma_m_s2, mag_sigma=mag_sigma,
                       declination_rad=noise.declination_rad, inclination_rad=incl)
            x[k] = ukf.state
        return np.column_stack(quat_to_euler(x[:, :4])), x[:, 4:]
    if name == "complementary":
        roll_pitch = euler_rate_complementary(dt, samples.gyro, samples.accel, 1.0)
        mag = np.where(np.isnan(samples.mag), 0.0, samples.mag)
        yaw = mag_heading(mag, roll_pitch[:, 0], roll_pitch[:, 1], noise.declination_rad)
        return np.column_stack([roll_pitch, yaw]), None
    raise ValueError(f"name: expected one of {ESTIMATORS}, got {name!r}")
