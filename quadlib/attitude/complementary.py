"""Complementary attitude filters: roll and pitch from gyro and accelerometer.

All three blend a gyro prediction with the accelerometer's tilt (:func:`quadlib.geometry.rotations.accel_tilt`):

.. math:: \\hat\\phi_k = a\\,\\bar\\phi_k + (1 - a)\\,\\phi^{acc}_k, \\qquad a = \\frac{\\tau}{\\tau + T_s}

— a low-pass on the accelerometer and a high-pass on the gyro, both with time constant τ.
They differ in the prediction ``φ̄_k``:

* :func:`linear_complementary` — Tellex eqs. (41)–(42): ``φ̄_k = φ̂_{k−1} + T_s p`` (body rates
  taken as Euler rates, eq. 39, valid near hover);
* :func:`euler_rate_complementary` — the blog's pipeline: body rates converted to Euler rates
  with :func:`quadlib.geometry.rotations.euler_rate_matrix` first;
* :func:`nonlinear_complementary` — Tellex eqs. (43)–(47): the previous attitude as a quaternion,
  turned by the measured body rates, then read back as roll and pitch.

Differs from the source: printed eqs. (46)–(47) add ``T_s z_θ`` to the predicted angle, which
already contains the gyro step, and write the accelerometer angle in its place; here the
predicted angle is used as is. The blog weights the *accelerometer* with α ≈ 0.95, which makes
``τ = T_s (1 − α)/α`` a small fraction of a sample: almost accelerometer-only (chapter 10).

Inputs: ``gyro`` and ``accel`` are ``(N, 3)`` samples at a uniform period ``dt``; ``gyro[k]``
is the rate over ``[t_k, t_{k+1}]``. The first estimate is ``initial`` (roll, pitch) when given,
else the accelerometer's tilt.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import called_from_python
from quadlib.geometry import kernels
from quadlib.geometry.rotations import accel_tilt
from quadlib.validation import as_bool, as_finite_array, as_float_array, as_positive, as_vector

__all__ = ["blend_weight", "euler_rate_complementary", "linear_complementary", "nonlinear_complementary"]


def blend_weight(tau: float, dt: float) -> float:
    """``a = τ / (τ + T_s)``, the weight of the gyro prediction."""
    tau, dt = as_positive("tau", tau, allow_zero=True), as_positive("dt", dt)
    return tau / (tau + dt)


def _inputs(gyro, accel, initial, a: float):
    """Gyro, accelerometer tilt, start, and each step's weight on the gyro: ``a``, or 1 where the
    accelerometer gives no tilt (a missing sample, free fall) — the gyro alone carries the step."""
    gyro, accel = as_finite_array("gyro", gyro, ndim=2), as_float_array("accel", accel)
    if gyro.shape[1] != 3 or accel.shape != gyro.shape:
        raise ValueError(f"gyro, accel: expected two (N, 3) arrays, got {gyro.shape} and {accel.shape}")
    tilt = np.column_stack(accel_tilt(accel))
    if initial is None and np.isnan(tilt[0]).any():
        raise ValueError("accel: expected a first sample that gives a tilt (not free fall, not NaN), or an initial "
                         f"roll and pitch, got |f| = {np.linalg.norm(accel[0]):.3g} m/s²")
    start = tilt[0] if initial is None else as_vector("initial", initial, 2)
    no_tilt = np.isnan(tilt).any(axis=1)
    weight = np.where(no_tilt, 1.0, a)
    return gyro, np.where(no_tilt[:, None], 0.0, tilt), start, weight


def linear_complementary(dt: float, gyro, accel, tau: float, initial=None) -> np.ndarray:
    """Tellex eqs. (41)–(42): ``(N, 2)`` roll and pitch [rad], gyro ``p, q`` used as Euler rates.

    A first-order recursion per angle; where the accelerometer gives no tilt the gyro alone moves it.
    """
    gyro, tilt, start, weight = _inputs(gyro, accel, initial, blend_weight(tau, dt))
    out = np.empty_like(tilt)
    out[0] = start
    for k in range(1, len(tilt)):
        out[k] = weight[k] * (out[k - 1] + dt * gyro[k - 1, :2]) + (1.0 - weight[k]) * tilt[k]
    return out


def euler_rate_complementary(dt: float, gyro, accel, tau: float, initial=None, compiled: bool = False) -> np.ndarray:
    """The blog's complementary filter: ``(N, 2)`` roll and pitch [rad], gyro rates turned into
    Euler rates with the current estimate before integrating. ``compiled=True`` runs the same loop
    compiled (:func:`_euler_rate_loop`, equal bit for bit, tested), for long logs."""
    compiled = as_bool("compiled", compiled)
    gyro, tilt, start, weight = _inputs(gyro, accel, initial, blend_weight(tau, dt))
    if compiled:
        return _euler_rate_loop(float(dt), gyro, tilt, float(start[0]), float(start[1]), weight)
    roll, pitch = (float(a) for a in start)
    out = [(roll, pitch)]
    # in Python floats (the same IEEE arithmetic as numpy's scalars, without their per-element cost)
    for (p, q, r), (tilt_roll, tilt_pitch), a in zip(gyro[:-1].tolist(), tilt[1:].tolist(), weight[1:].tolist(),
                                                     strict=True):
        sr, cr, tp = math.sin(roll), math.cos(roll), math.tan(pitch)
        roll_rate = p + (sr * q + cr * r) * tp  # first two rows of euler_rate_matrix
        pitch_rate = cr * q - sr * r
        roll = a * (roll + dt * roll_rate) + (1.0 - a) * tilt_roll
        pitch = a * (pitch + dt * pitch_rate) + (1.0 - a) * tilt_pitch
        out.append((roll, pitch))
    return np.array(out).reshape(-1, 2)


@called_from_python
@njit(cache=True)
def _euler_rate_loop(dt, gyro, tilt, roll, pitch, weight):
    """:func:`euler_rate_complementary`'s loop, compiled: the same expressions in the same order."""
    out = np.empty((tilt.shape[0], 2))
    out[0, 0], out[0, 1] = roll, pitch
    for k in range(1, tilt.shape[0]):
        p, q, r, a = gyro[k - 1, 0], gyro[k - 1, 1], gyro[k - 1, 2], weight[k]
        sr, cr, tp = math.sin(roll), math.cos(roll), math.tan(pitch)
        roll_rate = p + (sr * q + cr * r) * tp
        pitch_rate = cr * q - sr * r
        roll = a * (roll + dt * roll_rate) + (1.0 - a) * tilt[k, 0]
        pitch = a * (pitch + dt * pitch_rate) + (1.0 - a) * tilt[k, 1]
        out[k, 0], out[k, 1] = roll, pitch
    return out


def nonlinear_complementary(dt: float, gyro, accel, tau: float, yaw=None, initial=None) -> np.ndarray:
    """Tellex eqs. (43)–(47), corrected: ``(N, 2)`` roll and pitch [rad].

    Each step builds ``q̂`` from the last roll and pitch and a yaw (``yaw[k−1]`` when given, e.g.
    from a magnetometer or an EKF; otherwise the gyro-integrated yaw), turns it by the body
    rates (:func:`quadlib.geometry.quaternion.integrate_body_rate`), and blends its roll and pitch with
    the accelerometer's.
    """
    gyro, tilt, start, weight = _inputs(gyro, accel, initial, blend_weight(tau, dt))
    if yaw is not None:
        yaw = as_finite_array("yaw", yaw, ndim=1)
        if yaw.size != len(tilt):
            raise ValueError(f"yaw: expected shape ({len(tilt)},), got {yaw.shape}")
    out = np.empty_like(tilt)
    out[0] = start
    psi = 0.0 if yaw is None else yaw[0]
    for k in range(1, len(tilt)):
        if yaw is not None:
            psi = yaw[k - 1]
        # integrate_body_rate, quat_from_euler and quat_to_euler on one quaternion (geometry.kernels)
        q_prev = kernels.from_euler(out[k - 1, 0], out[k - 1, 1], psi)
        q_bar = kernels.multiply(q_prev, kernels.exp_rotvec(gyro[k - 1] * dt))
        roll_bar, pitch_bar, psi = kernels.to_euler(q_bar)
        out[k] = weight[k] * np.array([roll_bar, pitch_bar]) + (1.0 - weight[k]) * tilt[k]
    return out
