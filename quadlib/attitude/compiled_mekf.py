"""The orientation MEKF's loops, compiled: the filter :func:`~quadlib.replay.run_filter` runs, at C speed.

:func:`~quadlib.attitude.orientation.orientation_run` with ``compiled=False`` is the readable
filter — :class:`~quadlib.ModelEKF` on the attitude-and-bias model, its three sensors, driven by
``run_filter`` — and chapter 16 shows it. It costs about 300 µs a sample in each pass, and a
Python loop written for this one filter still costs about 110 µs (small numpy arrays: each
operation costs a microsecond whatever its size). So the same steps are written here once more,
as plain loops over floats that numba compiles; :mod:`tests.attitude.test_compiled_mekf`
checks that both give the same states and covariances to 1e-10, with dropouts, gate rejections,
rest, a saturated gyro and the smoother's backward pass.

Each step, as in ``run_filter`` with ``ModelEKF``:

* **predict** with the gyro sample (a NaN row holds the previous one): ``q ← q ⊗ exp((ω − b) Δt)``,
  ``P ← G P Gᵀ + Q`` with the error Jacobian of
  :func:`~quadlib.attitude.bias_model.gyro_error_jacobians` (``Q(Δt)`` reused while ``Δt`` stays
  within 1e-9 of the step it was computed for, as :class:`~quadlib.model_filter.ModelFilter`
  does), then ``q`` normalised;
* **updates**, in order gravity, heading, zero rate, each skipped where its sample is NaN: the
  innovation, ``S``, the χ² gate on the NIS, the gain (the heading's bias rows zero in the forward
  pass: a consider update), Joseph's covariance, and the error folded into ``q`` and ``b``.

The low-passes of rest detection and of the accelerometer are compiled here too; their readable
descriptions are :func:`~quadlib.attitude.orientation.rest_mask` and
:func:`~quadlib.attitude.orientation.inertial_lowpass`, which call them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    attitude_bias_jacobian,
    body_vector_jacobian,
    called_from_python,
    dcm,
    exp_rotvec,
    kalman_update,
    multiply,
    normalize,
    product,
    rate_matrix,
    rotvec,
    saturated,
    wrap,
)

__all__: list[str] = []  # internal: orientation.py is the interface


@njit(cache=True)
def _process_noise(sg, sb, dt):
    """``Q(Δt) = diag((σ_ω Δt)² I, σ_b² Δt I)`` (:func:`~quadlib.attitude.bias_model.attitude_bias_model`)."""
    a, c = (sg * dt) ** 2, sb**2 * dt
    return np.diag(np.array([a, a, a, c, c, c]))


@njit(cache=True)
def _add_jacobian(q):
    """``∂(x ⊞ δx)/∂δx`` at 0, ``(7, 6)``: ``½ Ξ(q)`` for the quaternion, the identity for the bias."""
    J = np.zeros((7, 6))
    J[:4, :3] = 0.5 * rate_matrix(q)
    J[4:, 3:] = np.eye(3)
    return J


@njit(cache=True)
def _fold(q, b, e):
    """The error into the state, ``q ⊗ exp(δθ)`` (normalised) and ``b + δb``."""
    if e[0] != 0.0 or e[1] != 0.0 or e[2] != 0.0 or e[3] != 0.0 or e[4] != 0.0 or e[5] != 0.0:
        q = multiply(q, exp_rotvec(e[:3]))
        b = b + e[3:]
    return normalize(q), b


@called_from_python
@njit(cache=True)
def mekf_pass(t, gyro, gravity_z, heading_z, heading_context, zero_rate_z, x0, P0, dt0, sg, sb, gravity_var,
              heading_var, zero_rate_var, gravity_gate, heading_gate, zero_rate_gate, gyro_range,
              heading_corrected, up):
    """The forward pass: ``gyro`` with its NaN rows already held (:func:`~quadlib.replay.held_inputs`).
    NaN rows of the ``*_z`` arrays (or of ``heading_context``) are missing samples; a gate ``≤ 0``
    means no gate; ``gyro_range ≤ 0`` a gyro that never saturates; ``heading_corrected`` is the
    heading gain's mask (:func:`~quadlib.compiled_kernels.kalman_update`).

    Returns ``x (N, 7)``, ``P (N, 6, 6)`` and, per sensor, ``innovation``, ``S``, ``nis``,
    ``used`` and ``rejected`` (NaN / False where the sample was missing)."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 7)), np.empty((n, 6, 6))
    inn_g, S_g = np.full((n, 3), np.nan), np.full((n, 3, 3), np.nan)
    inn_h, S_h = np.full((n, 1), np.nan), np.full((n, 1, 1), np.nan)
    inn_z, S_z = np.full((n, 3), np.nan), np.full((n, 3, 3), np.nan)
    nis, used, rejected = np.full((3, n), np.nan), np.zeros((3, n), np.bool_), np.zeros((3, n), np.bool_)
    q, b, P = normalize(x0[:4].copy()), x0[4:].copy(), P0.copy()
    q_dt = dt0
    Q = _process_noise(sg, sb, dt0)
    R_g, R_h, R_z = gravity_var * np.eye(3), np.full((1, 1), heading_var), zero_rate_var * np.eye(3)
    H_z = np.zeros((3, 6))
    H_z[:, 3:] = np.eye(3)
    every = np.ones(6, np.bool_)
    for k in range(n):
        if k:
            u = gyro[k - 1]
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt = dt
                Q = _process_noise(sg, sb, dt)
            phi = (u - b) * dt
            G = attitude_bias_jacobian(phi, dt)
            q = multiply(q, exp_rotvec(phi))
            P = product(product(G, P), G.T) + Q
            if saturated(u, gyro_range):
                for i in range(3):
                    P[i, i] += (gyro_range * dt) ** 2
            q = normalize(q)
        if not np.isnan(gravity_z[k]).any():  # gravity: h = R(q)ᵀ up
            H7 = np.zeros((3, 7))
            H7[:, :4] = body_vector_jacobian(q, up)
            y = gravity_z[k] - dcm(q).T @ up
            e, P, nis_k, S, ok = kalman_update(P, product(H7, _add_jacobian(q)), y, R_g, every, gravity_gate)
            inn_g[k], S_g[k], nis[0, k], used[0, k], rejected[0, k] = y, S, nis_k, ok, not ok
            if ok:
                q, b = _fold(q, b, e)
        if not np.isnan(heading_z[k]) and not np.isnan(heading_context[k]).any():  # heading about the vertical
            R = dcm(q)
            m_n = R @ heading_context[k]
            H7 = np.zeros((1, 7))
            H7[0, :4] = R[2] @ (2.0 * rate_matrix(q).T)
            y = np.array([wrap(heading_z[k] - math.atan2(m_n[1], m_n[0]))])
            e, P, nis_k, S, ok = kalman_update(P, product(H7, _add_jacobian(q)), y, R_h, heading_corrected,
                                               heading_gate)
            inn_h[k], S_h[k], nis[1, k], used[1, k], rejected[1, k] = y, S, nis_k, ok, not ok
            if ok:
                q, b = _fold(q, b, e)
        if not np.isnan(zero_rate_z[k]).any():  # the gyro at rest measures its bias
            y = zero_rate_z[k] - b
            e, P, nis_k, S, ok = kalman_update(P, H_z, y, R_z, every, zero_rate_gate)
            inn_z[k], S_z[k], nis[2, k], used[2, k], rejected[2, k] = y, S, nis_k, ok, not ok
            if ok:
                q, b = _fold(q, b, e)
        xs[k, :4], xs[k, 4:], Ps[k] = q, b, P
    return xs, Ps, (inn_g, S_g), (inn_h, S_h), (inn_z, S_z), nis, used, rejected


@called_from_python
@njit(cache=True)
def rts_pass(t, gyro, xs, Ps, sg, sb, gyro_range):
    """The Rauch–Tung–Striebel backward pass of :func:`~quadlib.replay.rts_smooth` for this model:
    ``gyro`` with NaN rows already held."""
    n = t.shape[0]
    xs_s, Ps_s = xs.copy(), Ps.copy()
    for k in range(n - 2, -1, -1):
        dt = t[k + 1] - t[k]
        x, P, u = xs[k], Ps[k], gyro[k]
        phi = (u - x[4:]) * dt
        F = attitude_bias_jacobian(phi, dt)
        prior_P = product(product(F, P), F.T) + _process_noise(sg, sb, dt)
        if saturated(u, gyro_range):
            for i in range(3):
                prior_P[i, i] += (gyro_range * dt) ** 2
        C = np.linalg.solve(prior_P, F @ P).T
        q_prior = multiply(x[:4], exp_rotvec(phi))
        # xs_s[k+1] ⊟ prior: the rotation vector of q_prior⁻¹ ⊗ q_s, and the bias difference
        q_s = xs_s[k + 1, :4]
        d = multiply(np.array([q_prior[0], -q_prior[1], -q_prior[2], -q_prior[3]]), q_s)
        diff = np.empty(6)
        diff[:3] = rotvec(d)
        diff[3:] = xs_s[k + 1, 4:] - x[4:]
        delta = C @ diff
        q_new = multiply(x[:4], exp_rotvec(delta[:3]))
        xs_s[k, :4] = normalize(q_new)
        xs_s[k, 4:] = x[4:] + delta[3:]
        P_s = P + (C @ (Ps_s[k + 1] - prior_P)) @ C.T
        Ps_s[k] = 0.5 * (P_s + P_s.T)
    return xs_s, Ps_s


@called_from_python
@njit(cache=True)
def calm_samples(t, gyro, accel, gyro_th, accel_th, tau):
    """:func:`~quadlib.attitude.orientation.rest_mask`'s first step: each sample within the
    thresholds of its stream's first-order low-pass."""
    n = t.shape[0]
    calm = np.zeros(n, np.bool_)
    lp_g, lp_a = np.zeros(3), np.zeros(3)
    started = False
    for k in range(n):
        g, a = gyro[k], accel[k]
        if np.isnan(g).any() or np.isnan(a).any():
            continue
        if not started:
            lp_g, lp_a, started = g.copy(), a.copy(), True
        else:
            w = (t[k] - t[k - 1]) / (tau + t[k] - t[k - 1])
            lp_g, lp_a = lp_g + w * (g - lp_g), lp_a + w * (a - lp_a)
        calm[k] = np.linalg.norm(g - lp_g) < gyro_th and np.linalg.norm(a - lp_a) < accel_th
    return calm


@called_from_python
@njit(cache=True)
def inertial_lowpass_pass(t, gyro, accel, usable, tau, backward):
    """One direction of :func:`~quadlib.attitude.orientation.inertial_lowpass`: the frame is
    integrated from the gyro over each step, forwards or backwards in time."""
    n = t.shape[0]
    out = np.full_like(accel, np.nan)
    q = np.array([1.0, 0.0, 0.0, 0.0])
    mean = np.zeros(3)
    have_mean = False
    previous = -1
    for i in range(n):
        k = n - 1 - i if backward else i
        if previous >= 0:  # turn the frame from the previous sample to this one
            step = t[k] - t[previous]
            rate = gyro[previous] if step > 0 else -gyro[k]
            q = multiply(q, exp_rotvec(rate * abs(step)))
        R = dcm(q)
        if usable[k]:
            a_i = R @ accel[k]
            dt = abs(t[k] - t[previous]) if previous >= 0 else 0.0
            if have_mean:
                mean = mean + dt / (tau + dt) * (a_i - mean)
            else:
                mean, have_mean = a_i, True
        if have_mean:
            out[k] = R.T @ mean
        previous = k
    return out
