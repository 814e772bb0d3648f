"""Kesten's five attitude filters, compiled: what :func:`~quadlib.replay.run_filter` does with each
:class:`~quadlib.attitude.kesten.KestenFilter` on :class:`~quadlib.ModelEKF`, at C speed.

The readable filters are the models and sensors of :mod:`quadlib.attitude.kesten`, which chapter 13
builds; run by ``run_filter`` they cost 50–130 µs a sample, nearly all of it the overhead of small
numpy arrays. The same steps are written here once more as one loop that numba compiles, with a
branch per filter where they differ; :mod:`tests.attitude.test_compiled_kesten` checks each against
its readable twin to 1e-10. Each step:

* **predict** with the gyro sample (a NaN row holds the previous one): the attitude turns by
  ``exp(ω Δt)`` — the orientation vector through its quaternion, the quaternion filters'
  quaternion directly — and ``P ← P + Q`` (every model's ``G`` is the identity), ``Q(Δt)`` reused
  while ``Δt`` stays within 1e-9 of the step it was computed for, plus the saturated-gyro variance;
  the quaternion is renormalised;
* **updates** with each present sample, in the filter's sensor order: the EKF update of
  :class:`~quadlib.ModelEKF` (Joseph's covariance) with the filter's ``h``, ``H`` and residual, the
  error folded into the quaternion for TQF and QF, the quaternion renormalised.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    body_vector_jacobian,
    called_from_python,
    dcm,
    diverged,
    exp_rotvec,
    kalman_update,
    multiply,
    normalize,
    rotvec,
    saturated,
)

__all__: list[str] = []  # internal: kesten.py is the interface

TOVKF, TQKF, TQF, QKF, QF = range(5)


@njit(cache=True)
def _nearest(z, x):
    """TOVKF's residual: ``z`` or the same attitude turned the other way round, whichever is nearer ``x``."""
    angle = np.linalg.norm(z)
    if angle < 1e-12:
        return z - x
    other = z - 2 * np.pi * z / angle
    return (z if np.linalg.norm(z - x) <= np.linalg.norm(other - x) else other) - x


@njit(cache=True)
def _turn_between(z, z_hat):
    """QF's residual: the rotation vector that turns the measured direction onto the predicted one."""
    ax, ay, az, bx, by, bz = z[0], z[1], z[2], z_hat[0], z_hat[1], z_hat[2]
    na, nb = math.sqrt(ax * ax + ay * ay + az * az), math.sqrt(bx * bx + by * by + bz * bz)
    ax, ay, az, bx, by, bz = ax / na, ay / na, az / na, bx / nb, by / nb, bz / nb
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    s = math.sqrt(cx * cx + cy * cy + cz * cz)
    if s < 1e-12:
        return np.zeros(3)
    angle = math.acos(min(1.0, max(-1.0, ax * bx + ay * by + az * bz)))
    return np.array([cx / s, cy / s, cz / s]) * angle


@njit(cache=True)
def _measure(kind, s, x, z, ref, n):
    """``H``, and the residual ``z ⊖ h(x)`` of sensor ``s`` of filter ``kind``."""
    if kind == TOVKF:
        return np.eye(3), _nearest(z, x)
    if kind == TQKF:
        return np.eye(4), (z if z @ x >= 0 else -z) - x
    if kind == TQF:
        z_hat = rotvec(x)
        q_hat = exp_rotvec(z_hat)
        return np.eye(3), rotvec(multiply(np.array([q_hat[0], -q_hat[1], -q_hat[2], -q_hat[3]]), exp_rotvec(z)))
    z_hat = dcm(x).T @ ref
    if kind == QKF:
        return body_vector_jacobian(x, ref), z - z_hat
    H = np.zeros((3, n))  # QF: the sensor's own error block
    for i in range(3):
        H[i, 3 * s + i] = 1.0
    return H, _turn_between(z, z_hat)


@njit(cache=True)
def _fold(kind, x, e):
    """The state after an update's correction ``e``: added, or for TQF and QF turned by each
    non-zero error block; the quaternion renormalised (not TOVKF's orientation vector)."""
    if kind == TOVKF:
        return x + e
    if kind == TQKF or kind == QKF:
        return normalize(x + e)
    q = x
    for b in range(e.shape[0] // 3):
        block = e[3 * b:3 * b + 3]
        if block[0] != 0.0 or block[1] != 0.0 or block[2] != 0.0:
            q = multiply(q, exp_rotvec(block))
    return normalize(q)


@called_from_python
@njit(cache=True)
def kesten_pass(kind, t, gyro, z0, present0, z1, present1, x0, P0, dt0, gyro_sigma, thesis_noise, q_scale,
                gyro_range, R0, R1, ref0, ref1):
    """Filter ``kind`` over a log: ``gyro`` with its NaN rows held, up to two sensors' samples
    ``z0``, ``z1`` with the rows they have (``present``), ``Q = q_scale · var(Δt) · I`` with
    ``var = Δt σ²`` (the thesis) or ``(σ Δt)²``; ``gyro_range ≤ 0``: a gyro that never saturates.

    Returns ``x (N, len(x0))``, ``P (N, n, n)``, then per sensor ``innovation``, ``S`` and ``nis``
    (NaN where no sample). Non-finite from the step where the estimate became so."""
    n_steps, n = t.shape[0], P0.shape[0]
    xs, Ps = np.empty((n_steps, x0.shape[0])), np.empty((n_steps, n, n))
    inn0, S0, nis0 = np.full((n_steps, z0.shape[1]), np.nan), np.full((n_steps, z0.shape[1], z0.shape[1]), np.nan), \
        np.full(n_steps, np.nan)
    inn1, S1, nis1 = np.full((n_steps, z1.shape[1]), np.nan), np.full((n_steps, z1.shape[1], z1.shape[1]), np.nan), \
        np.full(n_steps, np.nan)
    x, P = x0.copy(), P0.copy()
    every = np.ones(n, np.bool_)
    if kind != TOVKF:
        x = normalize(x)
    q_dt = dt0
    var = dt0 * gyro_sigma**2 if thesis_noise else (gyro_sigma * dt0) ** 2
    Q = q_scale * var * np.eye(n)
    for k in range(n_steps):
        if k:
            u, dt = gyro[k - 1], t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt = dt
                var = dt * gyro_sigma**2 if thesis_noise else (gyro_sigma * dt) ** 2
                Q = q_scale * var * np.eye(n)
            Q_k = Q
            if saturated(u, gyro_range):
                Q_k = Q + q_scale * (gyro_range * dt) ** 2 * np.eye(n)
            turn = exp_rotvec(u * dt)
            x = rotvec(multiply(exp_rotvec(x), turn)) if kind == TOVKF else normalize(multiply(x, turn))
            P = P + Q_k
        for s in range(2):
            if diverged(x, P):  # the caller hands the log to run_filter
                xs[k:], Ps[k:] = np.nan, np.nan
                return xs, Ps, inn0, S0, nis0, inn1, S1, nis1
            if not (present0[k] if s == 0 else present1[k]):
                continue
            z, R, ref = (z0[k], R0, ref0) if s == 0 else (z1[k], R1, ref1)
            H, y = _measure(kind, s, x, z, ref, n)
            e, P, nis_k, S, _ = kalman_update(P, H, y, R, every, 0.0)
            x = _fold(kind, x, e)
            if s == 0:
                inn0[k], S0[k], nis0[k] = y, S, nis_k
            else:
                inn1[k], S1[k], nis1[k] = y, S, nis_k
        xs[k], Ps[k] = x, P
    return xs, Ps, inn0, S0, nis0, inn1, S1, nis1
