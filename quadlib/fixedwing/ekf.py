"""Salmony's fixed-wing attitude EKF (§6–8) on quadlib's ModelEKF.

State ``[q0, q1, q2, q3, b_p, b_q, b_r]``, gyro as input. The prediction is the document's Euler
step ``x + T f(x, ω)`` (eq. 9) with the quaternion renormalised (§8.2); the covariance uses the
discrete form ``G P Gᵀ + Q`` with ``G = I + T A``, which differs from the document's
``P + T (A P + P Aᵀ + Q)`` by ``T² A P Aᵀ`` (chapter 12 measures it). The accelerometer model
depends on the gyro rates and the airspeed of the step, so its :class:`Sensor` is built per step.

Sensor failure (§8.3): a NaN magnetometer sample skips the magnetometer update; a NaN airspeed
switches the accelerometer to a model without the airspeed terms, whose covariance is inflated by
``unmodelled_m_s2`` for the centripetal acceleration it can no longer predict. Nothing is
re-created: the switch happens per step.
"""

from __future__ import annotations

import numpy as np

from quadlib.filters import ModelEKF
from quadlib.fixedwing.model import (
    accel_jacobian,
    accel_model,
    fixedwing_A,
    fixedwing_f,
    lowpass2,
    mag_jacobian,
    mag_model,
)
from quadlib.fixedwing.sim import FixedWingSamples
from quadlib.geometry.quaternion import quat_normalize
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.model import Model, Sensor
from quadlib.validation import as_positive

__all__ = ["fixedwing_accel_sensor", "fixedwing_mag_sensor", "fixedwing_model", "initial_state",
           "run_fixedwing_ekf"]


def fixedwing_model(sigma_gyro_rad_s: float, sigma_bias_walk_rad_s_sqrt_s: float) -> Model:
    """Eqs. (9)–(12), corrected (E18, E19), with gyro noise and a bias random walk as process noise."""
    sg = as_positive("sigma_gyro_rad_s", sigma_gyro_rad_s)
    sb = as_positive("sigma_bias_walk_rad_s_sqrt_s", sigma_bias_walk_rad_s_sqrt_s)

    def g(x, u, dt):
        x_new = x + dt * fixedwing_f(x, u)
        return np.concatenate([quat_normalize(x_new[:4]), x_new[4:]])

    return Model(state_names=("q0", "q1", "q2", "q3", "b_p [rad/s]", "b_q [rad/s]", "b_r [rad/s]"),
                 input_names=("p [rad/s]", "q [rad/s]", "r [rad/s]"), g=g,
                 G=lambda x, u, dt: np.eye(7) + dt * fixedwing_A(x, u),
                 Q=lambda dt: np.diag([0.25 * (sg * dt) ** 2] * 4 + [sb**2 * dt] * 3), name="Salmony fixed-wing")


def fixedwing_accel_sensor(omega, airspeed_m_s, sigma_m_s2: float, unmodelled_m_s2: float = 3.0) -> Sensor:
    """Eq. (13) for this step's gyro rates and airspeed; ``airspeed_m_s=None`` drops its terms."""
    s = as_positive("sigma_m_s2", sigma_m_s2)
    omega = np.asarray(omega, dtype=float)
    va = 0.0 if airspeed_m_s is None else float(airspeed_m_s)
    var = s**2 + (as_positive("unmodelled_m_s2", unmodelled_m_s2) ** 2 if airspeed_m_s is None else 0.0)
    return Sensor(name="accel", measurement_names=("ax", "ay", "az"), h=lambda x: accel_model(x, omega, va),
                  H=lambda x: accel_jacobian(x, omega, va), R=var * np.eye(3))


def fixedwing_mag_sensor(declination_rad: float, sigma: float, inclination_rad: float = 0.0) -> Sensor:
    """Eq. (14), corrected (E20); ``inclination_rad = 0`` is the document's horizontal field."""
    s = as_positive("sigma", sigma)
    return Sensor(name="mag", measurement_names=("mx", "my", "mz"),
                  h=lambda x: mag_model(x, declination_rad, inclination_rad),
                  H=lambda x: mag_jacobian(x, declination_rad, inclination_rad), R=s**2 * np.eye(3))


def initial_state(samples: FixedWingSamples, n_still: int) -> np.ndarray:
    """§8.1: the gyro bias as the mean of the first ``n_still`` gyro samples, the attitude from their
    mean accelerometer and magnetometer vectors. The samples must come from an unaccelerated,
    non-rotating stretch: at rest, or in steady straight and level flight."""
    if not isinstance(n_still, (int, np.integer)) or n_still < 1:
        raise ValueError(f"n_still: expected an int >= 1, got {n_still!r}")
    att = attitude_from_accel_mag(samples.accel[:n_still].mean(axis=0)[None], samples.mag[:n_still].mean(axis=0)[None])
    return np.concatenate([att.q_nb[0], samples.gyro[:n_still].mean(axis=0)])


def run_fixedwing_ekf(ekf: ModelEKF, dt: float, samples: FixedWingSamples, mag_sensor: Sensor, accel_sigma: float,
                      prefilter_hz: float | None = None, unmodelled_m_s2: float = 3.0):
    """Run the EKF over the samples; returns ``(x (N, 7), sigma (N, 7))``.

    ``prefilter_hz`` low-passes the accelerometer and magnetometer first (eqs. 7–8). NaN rows in
    ``samples.mag`` or NaN entries in ``samples.airspeed`` switch the measurement model that step.
    """
    if not isinstance(samples, FixedWingSamples):
        raise TypeError(f"samples: expected FixedWingSamples, got {type(samples).__name__}")
    n = len(samples.gyro)
    shapes = [np.shape(a) for a in samples]
    if shapes != [(n, 3), (n, 3), (n, 3), (n,)]:
        raise ValueError(f"samples: expected gyro, accel, mag of shape (N, 3) and airspeed of shape (N,), got {shapes}")
    dt = as_positive("dt", dt)
    accel, mag = samples.accel, samples.mag
    if prefilter_hz is not None:
        accel, mag = lowpass2(accel, prefilter_hz, dt), lowpass2(np.nan_to_num(mag), prefilter_hz, dt)
        mag[np.isnan(samples.mag).any(axis=1)] = np.nan
    xs, sigmas = np.empty((n, 7)), np.empty((n, 7))
    for k in range(n):
        if k:
            ekf.predict(samples.gyro[k - 1], dt)
        va = None if np.isnan(samples.airspeed[k]) else samples.airspeed[k]
        ekf.update_sensor(fixedwing_accel_sensor(samples.gyro[k], va, accel_sigma, unmodelled_m_s2),
                          accel[k])
        if not np.isnan(mag[k]).any():
            ekf.update_sensor(mag_sensor, mag[k])
        x = ekf.estimate
        ekf.x = np.concatenate([quat_normalize(x[:4]), x[4:]]).reshape(-1, 1)  # §8.2
        xs[k], sigmas[k] = ekf.estimate, np.sqrt(np.diag(ekf.P))
    return xs, sigmas
