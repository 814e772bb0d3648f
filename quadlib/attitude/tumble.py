"""A random tumbling motion and the IMU and magnetometer samples of it (Kesten §5.1.2's test).

The body rate is a smooth random signal (a sum of sinusoids with random directions, phases and
periods of 1–10 s), integrated exactly (eq. 2.7) into the true attitude. There is no linear
acceleration: the accelerometer reads ``−R_nbᵀ g_n`` only (Kesten's "random attitude rotation").
"""

from __future__ import annotations

import numpy as np

from quadlib.kernels.quaternion import exp_rotvec, multiply
from quadlib.sim.imu import BodyMotion, specific_force_at_rest
from quadlib.validation import as_count, as_finite_number, as_positive, as_rng

__all__ = ["random_rotation", "with_spin"]


def random_rotation(duration_s: float, rate_hz: float, rng, rms_rate_rad_s: float = 1.0,
                    n_terms: int = 12) -> BodyMotion:
    """A tumble of ``duration_s`` sampled at ``rate_hz`` (Kesten's IMU: 250 Hz), starting level and north."""
    rng = as_rng(rng)
    n_terms = as_count("n_terms", n_terms)
    dt = 1.0 / as_positive("rate_hz", rate_hz)
    t = np.arange(int(round(as_positive("duration_s", duration_s) / dt)) + 1) * dt
    axes = rng.normal(size=(n_terms, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    freqs = 2 * np.pi / rng.uniform(1.0, 10.0, n_terms)
    phases = rng.uniform(0, 2 * np.pi, n_terms)
    omega = (np.sin(np.outer(t, freqs) + phases) @ axes) * as_positive("rms_rate_rad_s", rms_rate_rad_s) * np.sqrt(
        2.0 / n_terms)
    return _at_rest(t, omega, np.array([1.0, 0.0, 0.0, 0.0]), dt)


def with_spin(motion: BodyMotion, start_s: float, duration_s: float, rate_rad_s: float) -> BodyMotion:
    """``motion`` (a tumble at rest) with ``rate_rad_s`` added about body x over
    ``[start_s, start_s + duration_s)``, the attitude re-integrated from there on."""
    if not isinstance(motion, BodyMotion):
        raise TypeError(f"motion: expected a BodyMotion, got {type(motion).__name__}")
    omega = motion.omega_b.copy()
    start_s = as_finite_number("start_s", start_s)
    window = (motion.t >= start_s) & (motion.t < start_s + as_positive("duration_s", duration_s))
    if not window.any():
        raise ValueError(f"start_s: expected a time within the motion [{motion.t[0]}, {motion.t[-1]}] s, "
                         f"got {start_s}")
    omega[window, 0] += as_finite_number("rate_rad_s", rate_rad_s)
    return _at_rest(motion.t, omega, motion.q_nb[0], motion.t[1] - motion.t[0])


def _at_rest(t, omega, q0, dt: float) -> BodyMotion:
    """Body rates ``omega`` integrated exactly (eq. 2.7) from ``q0`` over steps of ``dt``, no
    linear acceleration."""
    q = np.empty((t.size, 4))
    q[0] = q0
    for k in range(1, t.size):  # integrate_body_rate on one quaternion, unchecked (the same bits)
        q[k] = multiply(q[k - 1], exp_rotvec(omega[k - 1] * dt))
    return BodyMotion(t=t, q_nb=q, omega_b=omega, f_b=specific_force_at_rest(q))
