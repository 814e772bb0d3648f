"""Salmony's EKF loop, compiled: what :func:`~quadlib.replay.run_filter` does with
:func:`~quadlib.fixedwing.estimate.salmony_ekf` and the sensors of
:func:`~quadlib.fixedwing.estimate.fixedwing_measurements`, at C speed.

The readable filter is :class:`~quadlib.ModelEKF` on :func:`~quadlib.fixedwing.model.fixedwing_model`,
driven by ``run_filter``; chapter 12 builds it in view. It costs a few hundred microseconds a
sample, nearly all of it the overhead of small numpy arrays, so the same steps are written here
once more as plain loops that numba compiles (as :mod:`quadlib.attitude.compiled_mekf` does for
the orientation MEKF). :mod:`tests.fixedwing.test_compiled_ekf` checks that both give the same
states, covariances and sensor traces to 1e-10, with dropouts, a failed pitot, gate rejections and
a saturated gyro.

Each step, as in ``run_filter`` with ``ModelEKF``:

* **predict** with the gyro sample (a NaN row holds the previous one):
  ``x ← [q ⊗ exp((ω − b) Δt), b]``, ``P ← G P Gᵀ + Q`` with the step's exact Jacobian
  (:func:`~quadlib.attitude.bias_model.gyro_step_jacobian`; ``Q(Δt)`` reused while ``Δt`` stays
  within 1e-9 of the step it was computed for), then the renormalisation ``P ← J P Jᵀ``,
  ``q ← q / |q|`` (:func:`~quadlib.attitude.bias_model.normalize_attitude_jacobian`);
* **updates**, in order accelerometer with airspeed, accelerometer without, magnetometer, each
  skipped where its sample or context is NaN: the innovation, ``S``, the χ² gate on the NIS, the
  gain, Joseph's covariance, ``x ← x + K y`` and the renormalisation again.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.attitude.compiled_mekf import _body_vector_jacobian, _dcm, _exp_rotvec, _multiply, _rate_matrix, _update
from quadlib.imu import SATURATED

__all__: list[str] = []  # internal: estimate.py is the interface


@njit(cache=True)
def _step_jacobian(q, phi, dt):
    """``∂[q ⊗ exp(φ), b]/∂[q, b]`` with ``φ = (ω − b) Δt``, ``(7, 7)``
    (:func:`~quadlib.attitude.bias_model.gyro_step_jacobian`)."""
    theta = math.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    c = math.cos(theta / 2.0)
    sinc = math.sin(0.5 * theta) / theta if theta > 1e-6 else 0.5 - theta**2 / 48.0  # sin(θ/2)/θ
    k = (0.5 * c - sinc) / theta**2 if theta > 1e-3 else -1.0 / 24.0 + theta**2 / 960.0
    v0, v1, v2 = sinc * phi[0], sinc * phi[1], sinc * phi[2]
    J = np.eye(7)
    J[:4, :4] = np.array([[c, -v0, -v1, -v2], [v0, c, v2, -v1], [v1, -v2, c, v0], [v2, v1, -v0, c]])
    d_w = -0.5 * sinc * phi  # ∂cos(θ/2)/∂φ
    d_v = sinc * np.eye(3) + k * np.outer(phi, phi)  # ∂(sin(θ/2)/θ · φ)/∂φ
    J[:4, 4:] = -dt * (np.outer(q, d_w) + _rate_matrix(q) @ d_v)
    return J


@njit(cache=True)
def _renormalized(x, P):
    """``q / |q|`` and ``J P Jᵀ`` with ``J = (I − q̂ q̂ᵀ)/|q|`` on the quaternion, the identity on the biases."""
    q = x[:4]
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    q_hat = q / norm
    J = np.eye(7)
    J[:4, :4] = (np.eye(4) - np.outer(q_hat, q_hat)) / norm
    x_new = x.copy()
    x_new[:4] = q / norm
    return x_new, (J @ P) @ J.T


@njit(cache=True)
def _accel(x, omega, airspeed, g):
    """Eq. (13) and its Jacobian (:func:`~quadlib.fixedwing.model.accel_model`, ``accel_jacobian``)."""
    w, qx, qy, qz = x[0], x[1], x[2], x[3]
    q, r = omega[1] - x[5], omega[2] - x[6]
    down = (2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy))  # R(q)ᵀ [0, 0, 1]
    h = np.array([-g * down[0], airspeed * r - g * down[1], -airspeed * q - g * down[2]])
    C = np.zeros((3, 7))
    C[0, :4] = np.array([2 * g * qy, -2 * g * qz, 2 * g * w, -2 * g * qx])
    C[1, :4] = np.array([-2 * g * qx, -2 * g * w, -2 * g * qz, -2 * g * qy])
    C[2, :4] = np.array([0.0, 4 * g * qx, 4 * g * qy, 0.0])
    C[1, 6], C[2, 5] = -airspeed, airspeed
    return h, C


@njit(cache=True)
def _mag(x, field_n):
    """Eq. (14), corrected, and its Jacobian (:func:`~quadlib.fixedwing.model.mag_model`, ``mag_jacobian``)."""
    q = x[:4]
    h = _dcm(q).T @ field_n + (1.0 - q @ q) * field_n
    C = np.zeros((3, 7))
    C[:, :4] = _body_vector_jacobian(q, field_n) - 2.0 * np.outer(field_n, q)
    return h, C


@njit(cache=True)
def salmony_pass(t, gyro, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z, x0, P0, dt0, sg, sb,
                 gyro_range, R_accel, R_no_airspeed, R_mag, field_n, g, gate):
    """The filter over a log: ``gyro`` with its NaN rows already held
    (:func:`~quadlib.replay.held_inputs`); NaN rows of the ``*_z`` arrays or their contexts
    (``[p, q, r, V_a]`` and ``[p, q, r]``) are missing samples; ``gate ≤ 0`` means no gate,
    ``gyro_range ≤ 0`` a gyro that never saturates. From the step where the estimate becomes
    non-finite on, ``x`` and ``P`` are NaN.

    Returns ``x (N, 7)``, ``P (N, 7, 7)`` and, per sensor, ``innovation (N, 3)``, ``S (N, 3, 3)``,
    and ``nis``, ``used``, ``rejected`` ``(3, N)`` (NaN / False where the sample was missing)."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 7)), np.empty((n, 7, 7))
    innovations, Ss = np.full((3, n, 3), np.nan), np.full((3, n, 3, 3), np.nan)
    nis, used, rejected = np.full((3, n), np.nan), np.zeros((3, n), np.bool_), np.zeros((3, n), np.bool_)
    x, P = x0.copy(), P0.copy()
    x[:4] = x[:4] / math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
    q_dt = dt0
    quarter = np.array([0.25, 0.25, 0.25, 0.25, 0.0, 0.0, 0.0])
    Q = np.diag(np.array([0.25 * (sg * dt0) ** 2] * 4 + [sb**2 * dt0] * 3))
    for k in range(n):
        if k:
            u = gyro[k - 1]
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt = dt
                Q = np.diag(np.array([0.25 * (sg * dt) ** 2] * 4 + [sb**2 * dt] * 3))
            Q_k = Q
            if gyro_range > 0.0 and np.abs(u).max() >= SATURATED * gyro_range:
                Q_k = Q + (gyro_range * dt) ** 2 * np.diag(quarter)
            phi = (u - x[4:]) * dt
            G = _step_jacobian(x[:4], phi, dt)
            x_new = x.copy()
            x_new[:4] = _multiply(x[:4], _exp_rotvec(phi))
            P = (G @ P) @ G.T + Q_k
            x, P = _renormalized(x_new, P)
        for s in range(3):
            if not (np.isfinite(x).all() and np.isfinite(P).all()):  # diverged: the caller names where
                xs[k:], Ps[k:] = np.nan, np.nan
                return xs, Ps, innovations, Ss, nis, used, rejected
            if s == 0:
                z, c, R = accel_z[k], accel_context[k], R_accel
            elif s == 1:
                z, c, R = no_airspeed_z[k], no_airspeed_context[k], R_no_airspeed
            else:
                z, c, R = mag_z[k], mag_z[k], R_mag  # the field needs no context
            if np.isnan(z).any() or np.isnan(c).any():
                continue
            if s == 2:
                h, H = _mag(x, field_n)
            else:
                h, H = _accel(x, c, c[3] if s == 0 else 0.0, g)
            y = z - h
            dx, P_new, nis_k, S, ok = _update(P, H, y, R, 7, gate)
            innovations[s, k], Ss[s, k], nis[s, k], used[s, k], rejected[s, k] = y, S, nis_k, ok, not ok
            if ok:
                x, P = _renormalized(x + dx, P_new)
        xs[k], Ps[k] = x, P
    return xs, Ps, innovations, Ss, nis, used, rejected
