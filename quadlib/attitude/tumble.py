"""A random tumbling motion and the IMU and magnetometer samples of it (Kesten §5.1.2's test).

The body rate is a smooth random signal (a sum of sinusoids with random directions, phases and
periods of 1–10 s), integrated exactly (eq. 2.7) into the true attitude. There is no linear
acceleration: the accelerometer reads ``R_nbᵀ a_n`` only (Kesten's "random attitude rotation").
"""

from __future__ import annotations

import numpy as np

from quadlib.attitude.kesten import AttitudeNoise
from quadlib.geometry.quaternion import integrate_body_rate, quat_to_dcm
from quadlib.validation import as_positive, as_rng

__all__ = ["attitude_samples", "random_rotation"]


def random_rotation(duration_s: float, noise: AttitudeNoise, rng, rms_rate_rad_s: float = 1.0,
                    n_terms: int = 12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times ``(N,)``, true attitudes ``(N, 4)`` and body rates ``(N, 3)`` at the gyro period."""
    rng = as_rng(rng)
    t = np.arange(int(round(as_positive("duration_s", duration_s) / noise.tau)) + 1) * noise.tau
    axes = rng.normal(size=(n_terms, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    freqs = 2 * np.pi / rng.uniform(1.0, 10.0, n_terms)
    phases = rng.uniform(0, 2 * np.pi, n_terms)
    omega = (np.sin(np.outer(t, freqs) + phases) @ axes) * as_positive("rms_rate_rad_s", rms_rate_rad_s) * np.sqrt(
        2.0 / n_terms)
    q = np.empty((t.size, 4))
    q[0] = [1.0, 0.0, 0.0, 0.0]
    for k in range(1, t.size):
        q[k] = integrate_body_rate(q[k - 1], omega[k - 1], noise.tau)
    return t, q, omega


def attitude_samples(q_true, omega, noise: AttitudeNoise, rng, mag_every: int = 1, accel_every: int = 1,
                     gyro_bias_rad_s=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gyro, accelerometer and magnetometer samples ``(N, 3)``; NaN rows where a sensor is silent.

    The magnetometer reports every ``mag_every``-th sample (Kesten's ``τ_m = k τ_a``).
    """
    rng = as_rng(rng)
    n = len(q_true)
    R = quat_to_dcm(q_true)
    gyro = omega + np.asarray(gyro_bias_rad_s, dtype=float) + rng.normal(0.0, noise.sigma_gyro, (n, 3))
    accel = np.einsum("nji,j->ni", R, noise.accel_n) + rng.normal(0.0, noise.sigma_accel, (n, 3))
    mag = np.einsum("nji,j->ni", R, noise.mag_n) + rng.normal(0.0, noise.sigma_mag, (n, 3))
    accel[np.arange(n) % accel_every != 0] = np.nan
    mag[np.arange(n) % mag_every != 0] = np.nan
    return gyro, accel, mag
