"""Chapter 15's two fixed-wing filters, compiled: what :func:`~quadlib.replay.run_filter` does with
:func:`~quadlib.fixedwing.estimate.salmony_ekf` or :func:`~quadlib.fixedwing.estimate.error_state_ukf`
and the sensors of :func:`~quadlib.fixedwing.estimate.fixedwing_measurements`, at C speed.

The readable filters are :class:`~quadlib.ModelEKF` and :class:`~quadlib.ModelUKF` driven by
``run_filter``; chapter 15 builds the EKF in view. They cost a few hundred microseconds (the EKF)
and about a millisecond (the UKF) a sample, nearly all of it the overhead of small numpy arrays,
so the same steps are written here once more as plain loops that numba compiles (the orientation
MEKF runs on :mod:`quadlib.engine` instead, which these will move onto).
:mod:`tests.fixedwing.test_compiled` checks that each gives the same states, covariances and
sensor traces as its readable twin to 1e-10, with dropouts, a failed pitot, gate rejections and a
saturated gyro.

Each step, as in ``run_filter``:

* **predict** with the gyro sample (a NaN row holds the previous one), ``Q(Δt)`` reused while
  ``Δt`` stays within 1e-9 of the step it was computed for.
  Salmony's EKF: ``x ← [q ⊗ exp((ω − b) Δt), b]``, ``P ← G P Gᵀ + Q`` with the step's exact
  Jacobian (:func:`~quadlib.attitude.bias_model.gyro_step_jacobian`), then the renormalisation
  ``P ← J P Jᵀ``, ``q ← q / |q|`` (:func:`~quadlib.attitude.bias_model.normalize_attitude_jacobian`).
  The error-state UKF: each sigma point of ``[δθ, δb]`` is added to the state, stepped, and
  measured from the stepped state; their weighted mean and spread plus ``Q`` are the new error and
  covariance, and the mean error is folded into the state;
* **updates**, in order accelerometer with airspeed, accelerometer without, magnetometer, each
  skipped where its sample or context is NaN: the innovation, ``S``, the χ² gate on the NIS, then
  the EKF's gain and Joseph's covariance, or the UKF's gain from the sigma points' cross-covariance
  and ``P − K S Kᵀ`` (kept positive definite as :class:`~quadlib.ModelUKF` does), and the
  correction folded into the state.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    add_outer,
    body_vector_jacobian,
    called_from_python,
    dcm,
    diverged,
    exp_rotvec,
    kalman_update,
    matrix,
    multiply,
    normalize,
    positive_definite,
    product,
    rate_matrix,
    rotvec,
    saturated,
    upper_cholesky,
)

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
    J[:4, :4] = matrix(4, 4, (c, -v0, -v1, -v2, v0, c, v2, -v1, v1, -v2, c, v0, v2, v1, -v0, c))
    d_w = -0.5 * sinc * phi  # ∂cos(θ/2)/∂φ
    d_v = sinc * np.eye(3) + k * np.outer(phi, phi)  # ∂(sin(θ/2)/θ · φ)/∂φ
    J[:4, 4:] = -dt * (np.outer(q, d_w) + rate_matrix(q) @ d_v)
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
    return x_new, product(product(J, P), J.T)


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
    h = dcm(q).T @ field_n + (1.0 - q @ q) * field_n
    C = np.zeros((3, 7))
    C[:, :4] = body_vector_jacobian(q, field_n) - 2.0 * np.outer(field_n, q)
    return h, C


@njit(cache=True)
def _sample(s, k, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z):
    """Sensor ``s``'s sample at step ``k``, its context and whether it is there (no NaN in either)."""
    if s == 0:
        z, c = accel_z[k], accel_context[k]
    elif s == 1:
        z, c = no_airspeed_z[k], no_airspeed_context[k]
    else:
        z, c = mag_z[k], mag_z[k]  # the field needs no context
    return z, c, not (np.isnan(z).any() or np.isnan(c).any())


@njit(cache=True)
def _predicted(s, x, c, field_n, g):
    """``h(x)`` and ``∂h/∂x`` of sensor ``s`` (0: accelerometer with airspeed ``c[3]``, 1: without, 2: field)."""
    if s == 2:
        return _mag(x, field_n)
    return _accel(x, c, c[3] if s == 0 else 0.0, g)


@njit(cache=True)
def _gyro_step(x, u, dt):
    """``[q ⊗ exp((ω − b) Δt), b]`` (:func:`~quadlib.attitude.bias_model.gyro_step`)."""
    x_new = x.copy()
    x_new[:4] = multiply(x[:4], exp_rotvec((u - x[4:]) * dt))
    return x_new


@called_from_python
@njit(cache=True)
def salmony_pass(t, gyro, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z, x0, P0, dt0, sg, sb,
                 gyro_range, R, field_n, g, gate):
    """Salmony's EKF over a log: ``gyro`` with its NaN rows already held
    (:func:`~quadlib.replay.held_inputs`); NaN rows of the ``*_z`` arrays or their contexts
    (``[p, q, r, V_a]`` and ``[p, q, r]``) are missing samples; ``R`` ``(3, 3, 3)`` holds the three
    sensors' noise; ``gate ≤ 0`` means no gate, ``gyro_range ≤ 0`` a gyro that never saturates.
    From the step where the estimate becomes non-finite on, ``x`` and ``P`` are NaN.

    Returns ``x (N, 7)``, ``P (N, 7, 7)`` and, per sensor, ``innovation (N, 3)``, ``S (N, 3, 3)``,
    and ``nis``, ``used``, ``rejected`` ``(3, N)`` (NaN / False where the sample was missing)."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 7)), np.empty((n, 7, 7))
    innovations, Ss = np.full((3, n, 3), np.nan), np.full((3, n, 3, 3), np.nan)
    nis, used, rejected = np.full((3, n), np.nan), np.zeros((3, n), np.bool_), np.zeros((3, n), np.bool_)
    x, P = x0.copy(), P0.copy()
    every = np.ones(7, np.bool_)
    x[:4] = normalize(x[:4])
    quarter = np.diag(np.array([0.25, 0.25, 0.25, 0.25, 0.0, 0.0, 0.0]))  # a quaternion component per radian
    q_dt, Q = dt0, np.diag(np.array([0.25 * (sg * dt0) ** 2] * 4 + [sb**2 * dt0] * 3))
    for k in range(n):
        if k:
            u, dt = gyro[k - 1], t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, np.diag(np.array([0.25 * (sg * dt) ** 2] * 4 + [sb**2 * dt] * 3))
            Q_k = Q + (gyro_range * dt) ** 2 * quarter if saturated(u, gyro_range) else Q
            G = _step_jacobian(x[:4], (u - x[4:]) * dt, dt)
            x, P = _renormalized(_gyro_step(x, u, dt), product(product(G, P), G.T) + Q_k)
        for s in range(3):
            if diverged(x, P):  # the caller hands the log to run_filter, which names the step
                xs[k:], Ps[k:] = np.nan, np.nan
                return xs, Ps, innovations, Ss, nis, used, rejected
            z, c, present = _sample(s, k, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z)
            if not present:
                continue
            h, H = _predicted(s, x, c, field_n, g)
            y = z - h
            dx, P_new, nis_k, S, ok = kalman_update(P, H, y, R[s], every, gate)
            innovations[s, k], Ss[s, k], nis[s, k], used[s, k], rejected[s, k] = y, S, nis_k, ok, not ok
            if ok:
                x, P = _renormalized(x + dx, P_new)
        xs[k], Ps[k] = x, P
    return xs, Ps, innovations, Ss, nis, used, rejected


@njit(cache=True)
def _add_error(x, e):
    """``x ⊞ δx = [q ⊗ exp(δθ), b + δb]``."""
    x_new = np.empty(7)
    x_new[:4] = multiply(x[:4], exp_rotvec(e[:3]))
    x_new[4:] = x[4:] + e[3:]
    return x_new


@njit(cache=True)
def _error_between(x1, x0):
    """``x₁ ⊟ x₀ = [rotvec(q₀* ⊗ q₁), b₁ − b₀]``."""
    e = np.empty(6)
    e[:3] = rotvec(multiply(np.array([x0[0], -x0[1], -x0[2], -x0[3]]), x1[:4]))
    e[3:] = x1[4:] - x0[4:]
    return e


@njit(cache=True)
def _sigma_points(P, scale):
    """Van der Merwe's points about a zero error: ``0`` and ``±`` the rows of ``U``, ``Uᵀ U = scale · P``
    (filterpy's ``MerweScaledSigmaPoints``, ``scale = λ + n``); and whether ``P`` was positive definite."""
    n = P.shape[0]
    U, ok = upper_cholesky(scale * P)
    sigmas = np.zeros((2 * n + 1, n))
    sigmas[1:n + 1], sigmas[n + 1:] = U, -U
    return sigmas, ok


@called_from_python
@njit(cache=True)
def error_state_ukf_pass(t, gyro, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z, x0, P0, dt0,
                         sg, sb, gyro_range, R, field_n, g, gate, Wm, Wc, scale):
    """The error-state UKF over a log, with the arguments of :func:`salmony_pass` and the sigma
    points' weights ``Wm``, ``Wc`` and ``scale = λ + n``. A covariance that stops being positive
    definite where the sigma points need its factor counts as a divergence (``run_filter`` raises
    there). Returns what :func:`salmony_pass` does, with ``P (N, 6, 6)`` over ``[δθ, δb]``."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 7)), np.empty((n, 6, 6))
    innovations, Ss = np.full((3, n, 3), np.nan), np.full((3, n, 3, 3), np.nan)
    nis, used, rejected = np.full((3, n), np.nan), np.zeros((3, n), np.bool_), np.zeros((3, n), np.bool_)
    x, P = x0.copy(), P0.copy()
    x[:4] = normalize(x[:4])
    attitude = np.diag(np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0]))
    q_dt, Q = dt0, np.diag(np.array([(sg * dt0) ** 2] * 3 + [sb**2 * dt0] * 3))
    stepped = np.empty((2 * 6 + 1, 6))
    measured = np.empty((2 * 6 + 1, 3))
    for k in range(n):
        healthy = True
        if k:
            u, dt = gyro[k - 1], t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, np.diag(np.array([(sg * dt) ** 2] * 3 + [sb**2 * dt] * 3))
            Q_k = Q + (gyro_range * dt) ** 2 * attitude if saturated(u, gyro_range) else Q
            after = _gyro_step(x, u, dt)
            sigmas, ok = _sigma_points(P, scale)
            for i in range(sigmas.shape[0]):
                stepped[i] = _error_between(_gyro_step(_add_error(x, sigmas[i]), u, dt), after)
            e = Wm @ stepped
            d = stepped - e
            P = d.T @ (np.diag(Wc) @ d) + Q_k
            healthy = ok and upper_cholesky(scale * P)[1]  # filterpy draws the next points from it
            x = _normalize_state(_add_error(after, e) if e.any() else after)
        for s in range(3):
            if not healthy or diverged(x, P):
                break
            z, c, present = _sample(s, k, accel_z, accel_context, no_airspeed_z, no_airspeed_context, mag_z)
            if not present:
                continue
            sigmas, healthy = _sigma_points(P, scale)
            if not healthy:
                break
            for i in range(sigmas.shape[0]):
                measured[i] = _predicted(s, _add_error(x, sigmas[i]), c, field_n, g)[0]
            z_mean = Wm @ measured
            d = measured - z_mean
            S = d.T @ (np.diag(Wc) @ d) + R[s]
            SI = np.linalg.inv(S)
            Pxz = np.zeros((6, 3))
            for i in range(sigmas.shape[0]):
                add_outer(Pxz, Wc[i], sigmas[i], d[i])
            K = Pxz @ SI
            y = z - z_mean
            nis_k = (y @ SI) @ y
            ok = not (gate > 0.0 and nis_k > gate)
            innovations[s, k], Ss[s, k], nis[s, k], used[s, k], rejected[s, k] = y, S, nis_k, ok, not ok
            if ok:
                e = K @ y
                P = positive_definite(P - K @ (S @ K.T))
                x = _normalize_state(_add_error(x, e) if e.any() else x)
        if not healthy or diverged(x, P):  # the caller hands the log to run_filter, which names the step
            xs[k:], Ps[k:] = np.nan, np.nan
            return xs, Ps, innovations, Ss, nis, used, rejected
        xs[k], Ps[k] = x, P
    return xs, Ps, innovations, Ss, nis, used, rejected


@njit(cache=True)
def _normalize_state(x):
    x_new = x.copy()
    x_new[:4] = normalize(x[:4])
    return x_new
