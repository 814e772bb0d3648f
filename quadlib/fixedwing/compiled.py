"""Chapter 15's error-state UKF, compiled: what :func:`~quadlib.replay.run_filter` does with
:func:`~quadlib.fixedwing.estimate.error_state_ukf` and the sensors of
:func:`~quadlib.fixedwing.estimate.fixedwing_measurements`, at C speed.

The readable filter is :class:`~quadlib.ModelUKF` driven by ``run_filter``; it costs about a
millisecond a sample, nearly all of it the overhead of small numpy arrays, so its steps are
written here once more as a loop that numba compiles, calling the model's and the sensors' own
kernels (:mod:`quadlib.kernels.attitude`, :mod:`quadlib.kernels.fixedwing`). Salmony's EKF and the
multiplicative EKF run on the compiled engine (:mod:`quadlib.engine`); this loop moves there when
the engine has a UKF. :mod:`tests.fixedwing.test_compiled` checks that it gives the same states,
covariances and sensor traces as its readable twin to 1e-10, with dropouts, a failed pitot, gate
rejections and a saturated gyro.

Each step, as in ``run_filter``:

* **predict** with the gyro sample (a NaN row holds the previous one), ``Q(Δt)`` reused while
  ``Δt`` stays within 1e-9 of the step it was computed for: each sigma point of ``[δθ, δb]`` is
  added to the state, stepped, and measured from the stepped state; their weighted mean and spread
  plus ``Q`` are the new error and covariance, and the mean error is folded into the state;
* **updates**, in order accelerometer with airspeed, accelerometer without, magnetometer, each
  skipped where its sample or context is NaN: the innovation, ``S``, the χ² gate on the NIS, the
  UKF's gain from the sigma points' cross-covariance and ``P − K S Kᵀ`` (kept positive definite as
  :class:`~quadlib.ModelUKF` does), and the correction folded into the state.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    add_outer,
    called_from_python,
    diverged,
    positive_definite,
    saturated,
    upper_cholesky,
)
from quadlib.kernels.attitude import (
    attitude_bias_add,
    attitude_bias_difference,
    attitude_bias_step,
    normalize_quaternion,
)
from quadlib.kernels.fixedwing import airspeed_accel, unit_field

__all__: list[str] = []  # internal: estimate.py is the interface


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
    """``h(x)`` of sensor ``s`` (0: accelerometer with airspeed ``c[3]``, 1: without, 2: field)."""
    if s == 2:
        return unit_field(x, c, field_n)
    return airspeed_accel(x, c, np.array([g, 1.0 if s == 0 else 0.0]))


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
    """The error-state UKF over a log: ``gyro`` with its NaN rows already held
    (:func:`~quadlib.replay.held_inputs`); NaN rows of the ``*_z`` arrays or their contexts
    (``[p, q, r, V_a]`` and ``[p, q, r]``) are missing samples; ``R`` ``(3, 3, 3)`` holds the three
    sensors' noise; ``gate ≤ 0`` means no gate, ``gyro_range ≤ 0`` a gyro that never saturates;
    ``Wm``, ``Wc`` the sigma points' weights and ``scale = λ + n``. A covariance that stops being
    positive definite where the sigma points need its factor counts as a divergence (``run_filter``
    raises there), and from the step where the estimate becomes non-finite on, ``x`` and ``P`` are NaN.

    Returns ``x (N, 7)``, ``P (N, 6, 6)`` over ``[δθ, δb]`` and, per sensor, ``innovation (N, 3)``,
    ``S (N, 3, 3)``, and ``nis``, ``used``, ``rejected`` ``(3, N)`` (NaN / False where missing)."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 7)), np.empty((n, 6, 6))
    innovations, Ss = np.full((3, n, 3), np.nan), np.full((3, n, 3, 3), np.nan)
    nis, used, rejected = np.full((3, n), np.nan), np.zeros((3, n), np.bool_), np.zeros((3, n), np.bool_)
    no_params = np.zeros(0)  # the attitude kernels' parameters: they have none
    x, P = normalize_quaternion(x0, no_params), P0.copy()
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
            after = attitude_bias_step(x, u, dt, no_params)
            sigmas, ok = _sigma_points(P, scale)
            for i in range(sigmas.shape[0]):
                stepped[i] = attitude_bias_difference(
                    attitude_bias_step(attitude_bias_add(x, sigmas[i], no_params), u, dt, no_params), after, no_params)
            e = Wm @ stepped
            d = stepped - e
            P = d.T @ (np.diag(Wc) @ d) + Q_k
            healthy = ok and upper_cholesky(scale * P)[1]  # filterpy draws the next points from it
            x = normalize_quaternion(attitude_bias_add(after, e, no_params) if e.any() else after, no_params)
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
                measured[i] = _predicted(s, attitude_bias_add(x, sigmas[i], no_params), c, field_n, g)
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
                x = normalize_quaternion(attitude_bias_add(x, e, no_params) if e.any() else x, no_params)
        if not healthy or diverged(x, P):  # the caller hands the log to run_filter, which names the step
            xs[k:], Ps[k:] = np.nan, np.nan
            return xs, Ps, innovations, Ss, nis, used, rejected
        xs[k], Ps[k] = x, P
    return xs, Ps, innovations, Ss, nis, used, rejected
