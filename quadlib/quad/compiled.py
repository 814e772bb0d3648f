"""Chapter 11's UKF, compiled: what :func:`~quadlib.replay.run_filter` does with
:func:`~quadlib.quad.estimate.quad3d_ukf` and the GPS
and magnetometer of :class:`~quadlib.quad.estimate.Quad3DTuning` (no gate), at C speed.

The readable filter is :class:`~quadlib.ModelUKF` on :func:`~quadlib.quad.quad3d.quad3d_model`,
driven by ``run_filter``; chapter 11 builds it in view. It costs over a millisecond a step, nearly
all of it the overhead of small numpy arrays, so the same steps are written here as a loop that
numba compiles, calling the model's kernels (:mod:`quadlib.kernels.quad3d`); the EKF runs on the
compiled engine (:mod:`quadlib.engine`). :mod:`tests.quad.test_compiled` checks that it gives the
same states, covariances and sensor traces as its readable twin to 1e-10.

The sensors' samples arrive between the filter's steps. ``run_filter`` decides where each one is
applied (:func:`~quadlib.replay.sample_steps`); the caller passes that schedule as three arrays
of events — step, sensor (0 GPS, 1 magnetometer), sample — in the order ``run_filter`` applies
them. Each step:

* **predict** with the input of the step before (a NaN row holds the previous one), ``Q(Δt)``
  reused while ``Δt`` stays within 1e-9 of the step it was computed for: the sigma points move
  through ``g`` (eq. 49) and are averaged, the yaw on the circle;
* **updates** with that step's samples: GPS position and velocity (``h = x[:6]``) and the
  magnetometer's heading (``h = ψ``, innovations wrapped to (−π, π]).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import add_outer, called_from_python, diverged, positive_definite, upper_cholesky, wrap
from quadlib.kernels.quad3d import quad3d_noise, quad3d_step

__all__: list[str] = []  # internal: estimate.py is the interface

YAW = 6


@njit(cache=True)
def _outputs(n, k_gps, k_mag):
    return (np.empty((n, 7)), np.empty((n, 7, 7)), np.full((k_gps, 6), np.nan), np.full((k_gps, 6, 6), np.nan),
            np.full(k_gps, np.nan), np.full((k_mag, 1), np.nan), np.full((k_mag, 1, 1), np.nan),
            np.full(k_mag, np.nan))


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
def quad3d_ukf_pass(t, u, event_step, event_sensor, event_sample, gps_z, mag_z, x0, P0, dt0, g_params, q_params,
                    R_gps, R_mag, Wm, Wc, scale):
    """The UKF over a log: ``u`` with its NaN rows already held (:func:`~quadlib.replay.held_inputs`),
    the updates as events sorted as ``run_filter`` applies them (present, not repeated samples only);
    the model's kernels' parameters ``g_params``, ``q_params``; the sigma points' weights ``Wm``,
    ``Wc`` and ``scale = λ + n``. A covariance the sigma points cannot factor counts as a divergence
    (``run_filter`` raises there).

    Returns ``x (N, 7)``, ``P (N, 7, 7)``, then for the GPS and for the magnetometer ``innovation``,
    ``S`` and ``nis`` per sample (NaN where not applied). Non-finite from the step where the estimate
    became so."""
    n = t.shape[0]
    xs, Ps, inn_g, S_g, nis_g, inn_m, S_m, nis_m = _outputs(n, gps_z.shape[0], mag_z.shape[0])
    m = 2 * 7 + 1
    x, P = x0.copy(), P0.copy()
    q_dt, Q = dt0, quad3d_noise(dt0, q_params)
    stepped = np.empty((m, 7))
    e = 0
    for k in range(n):
        healthy = True
        if k:
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, quad3d_noise(dt, q_params)
            sigmas, healthy = _sigma_points(x, P, scale)
            for i in range(m):
                stepped[i] = quad3d_step(sigmas[i], u[k - 1], dt, g_params)
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
