"""Chapter 11's EKF and UKF, compiled: what :func:`~quadlib.replay.run_filter` does with
:func:`~quadlib.quad.estimate.quad3d_ekf` or :func:`~quadlib.quad.estimate.quad3d_ukf` and the GPS
and magnetometer of :class:`~quadlib.quad.estimate.Quad3DTuning` (no gate), at C speed.

The readable filters are :class:`~quadlib.ModelEKF` and :class:`~quadlib.ModelUKF` on
:func:`~quadlib.quad.quad3d.quad3d_model`, driven by ``run_filter``; chapter 11 builds them in view.
They cost about a hundred microseconds (the EKF) and over a millisecond (the UKF) a step, nearly
all of it the overhead of small numpy arrays, so the same steps are written here once more as
plain loops that numba compiles (as :mod:`quadlib.fixedwing.compiled` does for the fixed-wing
filters). :mod:`tests.quad.test_compiled` checks that each gives the same states, covariances and
sensor traces as its readable twin to 1e-10.

The sensors' samples arrive between the filter's steps. ``run_filter`` decides where each one is
applied (:func:`~quadlib.replay.sample_steps`); the caller passes that schedule as three arrays
of events — step, sensor (0 GPS, 1 magnetometer), sample — in the order ``run_filter`` applies
them. Each step:

* **predict** with the input of the step before (a NaN row holds the previous one), ``Q(Δt)``
  reused while ``Δt`` stays within 1e-9 of the step it was computed for: the EKF moves the mean
  with ``g`` (eq. 49) and the covariance with its Jacobian (eqs. 50–52); the UKF moves its sigma
  points through ``g`` and averages them, the yaw on the circle;
* **updates** with that step's samples: GPS position and velocity (``h = x[:6]``) and the
  magnetometer's heading (``h = ψ``, innovations wrapped to (−π, π]).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    add_outer,
    called_from_python,
    diverged,
    kalman_update,
    positive_definite,
    product,
    upper_cholesky,
    wrap,
)
from quadlib.geometry.kernels import euler_dcm

__all__: list[str] = []  # internal: estimate.py is the interface

YAW = 6


@njit(cache=True)
def _g(x, u, dt, g_down):
    """Eq. (49) with NED gravity ``g_down``, the yaw wrapped (:func:`~quadlib.quad.quad3d.quad3d_model`)."""
    R = euler_dcm(u[4], u[5], x[YAW])
    x_new = np.empty(7)
    x_new[:3] = x[:3] + x[3:6] * dt
    f_n = R @ u[:3]
    f_n[2] += g_down
    x_new[3:6] = x[3:6] + f_n * dt
    x_new[YAW] = math.pi - (math.pi - (x[YAW] + u[3] * dt)) % (2.0 * math.pi)
    return x_new


@njit(cache=True)
def _G(x, u, dt):
    """Eqs. (50)–(52): ``∂g/∂x``; the yaw column is ``∂R/∂ψ f Δt`` with rows ``(−R₁, R₀, 0)``."""
    J = np.eye(7)
    for i in range(3):
        J[i, 3 + i] = dt
    R = euler_dcm(u[4], u[5], x[YAW])
    f = u[:3] * dt
    J[3, YAW] = -(R[1] @ f)
    J[4, YAW] = R[0] @ f
    return J


@njit(cache=True)
def _Q(accel_sigma, yaw_rate_sigma, dt):
    """White acceleration per axis (``σ Δt²/2`` on position, ``σ Δt`` on velocity) and yaw rate."""
    Q = np.zeros((7, 7))
    for i in range(3):
        w0, w1 = 0.5 * dt**2 * accel_sigma[i], dt * accel_sigma[i]
        Q[i, i], Q[i, i + 3], Q[i + 3, i], Q[i + 3, i + 3] = w0 * w0, w0 * w1, w1 * w0, w1 * w1
    Q[YAW, YAW] = (yaw_rate_sigma * dt) ** 2
    return Q


@njit(cache=True)
def _outputs(n, k_gps, k_mag):
    return (np.empty((n, 7)), np.empty((n, 7, 7)), np.full((k_gps, 6), np.nan), np.full((k_gps, 6, 6), np.nan),
            np.full(k_gps, np.nan), np.full((k_mag, 1), np.nan), np.full((k_mag, 1, 1), np.nan),
            np.full(k_mag, np.nan))


@called_from_python
@njit(cache=True)
def quad3d_ekf_pass(t, u, event_step, event_sensor, event_sample, gps_z, mag_z, x0, P0, dt0, accel_sigma,
                    yaw_rate_sigma, g_down, R_gps, R_mag):
    """The EKF over a log: ``u`` with its NaN rows already held (:func:`~quadlib.replay.held_inputs`),
    the updates as events sorted as ``run_filter`` applies them (present, not repeated samples only).

    Returns ``x (N, 7)``, ``P (N, 7, 7)``, then for the GPS and for the magnetometer ``innovation``,
    ``S`` and ``nis`` per sample (NaN where not applied). Non-finite from the step where the estimate
    became so."""
    n = t.shape[0]
    xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m = _outputs(n, gps_z.shape[0], mag_z.shape[0])
    H_gps, H_mag = np.zeros((6, 7)), np.zeros((1, 7))
    H_gps[:, :6], H_mag[0, YAW] = np.eye(6), 1.0
    every = np.ones(7, np.bool_)
    x, P = x0.copy(), P0.copy()
    q_dt, Q = dt0, _Q(accel_sigma, yaw_rate_sigma, dt0)
    e = 0
    for k in range(n):
        if k:
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, _Q(accel_sigma, yaw_rate_sigma, dt)
            F = _G(x, u[k - 1], dt)
            x = _g(x, u[k - 1], dt, g_down)
            P = product(product(F, P), F.T) + Q
        while e < event_step.shape[0] and event_step[e] == k:
            if diverged(x, P):  # the caller hands the log to run_filter
                xs[k:], Ps[k:] = np.nan, np.nan
                return xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m
            j = event_sample[e]
            if event_sensor[e] == 0:
                y = gps_z[j] - x[:6]
                dx, P, nis_g[j], S_g[j], _ = kalman_update(P, H_gps, y, R_gps, every, 0.0)
                inn_g[j] = y
            else:
                y = np.array([wrap(mag_z[j, 0] - x[YAW])])
                dx, P, nis_m[j], S_m[j], _ = kalman_update(P, H_mag, y, R_mag, every, 0.0)
                inn_m[j] = y
            x = x + dx
            e += 1
        xs[k], Ps[k] = x, P
    return xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m


@njit(cache=True)
def _residual_x(a, b):
    """``a − b`` with the yaw difference wrapped (:func:`~quadlib.quad.quad3d.quad3d_ukf_options`)."""
    d = a - b
    d[YAW] = wrap(d[YAW])
    return d


@njit(cache=True)
def _sigma_points(x, P, scale):
    """Van der Merwe's points (filterpy's ``MerweScaledSigmaPoints`` with ``subtract=residual_x``):
    ``x`` and ``x ∓ (∓ rows of U)``, ``Uᵀ U = scale · P``, yaw wrapped; and whether ``P`` was
    positive definite."""
    n = x.shape[0]
    U, ok = upper_cholesky(scale * P)
    sigmas = np.empty((2 * n + 1, n))
    sigmas[0] = x
    for k in range(n):
        sigmas[k + 1] = _residual_x(x, -U[k])
        sigmas[n + k + 1] = _residual_x(x, U[k])
    return sigmas, ok


@njit(cache=True)
def _state_mean(sigmas, Wm):
    """The weighted mean with the yaw averaged on the circle."""
    mean = Wm @ sigmas
    mean[YAW] = math.atan2(Wm @ np.sin(sigmas[:, YAW]), Wm @ np.cos(sigmas[:, YAW]))
    return mean


@called_from_python
@njit(cache=True)
def quad3d_ukf_pass(t, u, event_step, event_sensor, event_sample, gps_z, mag_z, x0, P0, dt0, accel_sigma,
                    yaw_rate_sigma, g_down, R_gps, R_mag, Wm, Wc, scale):
    """The UKF over a log, with the arguments of :func:`quad3d_ekf_pass` and the sigma points'
    weights ``Wm``, ``Wc`` and ``scale = λ + n``. A covariance the sigma points cannot factor counts
    as a divergence (``run_filter`` raises there). Returns what :func:`quad3d_ekf_pass` does."""
    n = t.shape[0]
    xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m = _outputs(n, gps_z.shape[0], mag_z.shape[0])
    m = 2 * 7 + 1
    x, P = x0.copy(), P0.copy()
    q_dt, Q = dt0, _Q(accel_sigma, yaw_rate_sigma, dt0)
    stepped = np.empty((m, 7))
    e = 0
    for k in range(n):
        healthy = True
        if k:
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, _Q(accel_sigma, yaw_rate_sigma, dt)
            sigmas, healthy = _sigma_points(x, P, scale)
            for i in range(m):
                stepped[i] = _g(sigmas[i], u[k - 1], dt, g_down)
            x = _state_mean(stepped, Wm)
            P_sum = np.zeros((7, 7))
            for i in range(m):
                d = _residual_x(stepped[i], x)
                add_outer(P_sum, Wc[i], d, d)
            P = P_sum + Q
            healthy = healthy and upper_cholesky(scale * P)[1]  # filterpy draws the next points from it
        while healthy and e < event_step.shape[0] and event_step[e] == k:
            if diverged(x, P):
                healthy = False
                break
            sigmas, healthy = _sigma_points(x, P, scale)
            if not healthy:
                break
            j = event_sample[e]
            if event_sensor[e] == 0:  # GPS: the plain mean and spread
                measured = sigmas[:, :6].copy()
                z_mean = Wm @ measured
                d_z = measured - z_mean
                S = d_z.T @ (np.diag(Wc) @ d_z) + R_gps
                y = gps_z[j] - z_mean
            else:  # heading: mean on the circle, wrapped residuals
                z_mean = np.array([math.atan2(Wm @ np.sin(sigmas[:, YAW]), Wm @ np.cos(sigmas[:, YAW]))])
                d_z = np.empty((m, 1))
                for i in range(m):
                    d_z[i, 0] = wrap(sigmas[i, YAW] - z_mean[0])
                S = np.zeros((1, 1))
                for i in range(m):
                    add_outer(S, Wc[i], d_z[i], d_z[i])
                S = S + R_mag
                y = np.array([wrap(mag_z[j, 0] - z_mean[0])])
            SI = np.linalg.inv(S)
            Pxz = np.zeros((7, y.shape[0]))
            for i in range(m):
                add_outer(Pxz, Wc[i], _residual_x(sigmas[i], x), d_z[i])
            K = Pxz @ SI
            x = x + K @ y
            P = positive_definite(P - K @ (S @ K.T))
            nis = (y @ SI) @ y
            if event_sensor[e] == 0:
                inn_g[j], S_g[j], nis_g[j] = y, S, nis
            else:
                inn_m[j], S_m[j], nis_m[j] = y, S, nis
            e += 1
        if not healthy or diverged(x, P):
            xs[k:], Ps[k:] = np.nan, np.nan
            return xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m
        xs[k], Ps[k] = x, P
    return xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m
