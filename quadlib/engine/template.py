"""The engine's loop over a log, written once for every filter: :mod:`quadlib.engine.build` compiles a
copy of this file for each filter it runs, with that filter's kernels in place of the names below.

The names ``model_g``, ``model_G`` … are the model's kernels (:data:`~quadlib.engine.kernel.MODEL_ROLES`),
``sensor_h(s, …)`` … call sensor ``s``'s, ``sigma_difference`` and ``sigma_mean`` are a UKF's ``⊟`` and
mean of an additive state, and the upper-case flags say which of the model's optional kernels exist:
numba drops every branch a flag rules out, so each filter's machine code holds its own steps only.
Here they are :mod:`quadlib.engine.defaults`' stand-ins, so that this file reads, imports and lints as
the module it is copied to.

What a step does, as :func:`~quadlib.replay.run_filter` and the filterpy wrappers do it:

* **predict** (EKF) with the input of the step before (NaN rows already held): ``G`` at the previous
  state, ``Q(Δt)`` reused while ``Δt`` stays within 1e-9 of the step it was computed for (unless the
  filter's ``Q`` was set by hand, which holds), plus the input's noise, the mean through ``g``,
  ``P ← G P Gᵀ + Q``, then ``normalize`` (carrying ``P`` through its Jacobian for an additive model
  that has one);
* **predict** (UKF): Van der Merwe's sigma points from ``U = chol((λ + n) P)`` — an additive state's
  ``x ⊟ ∓Uₖ``, an error-state model's ``±Uₖ`` added with ``⊞`` — through ``g`` (an error-state
  model's as ``g(x ⊞ δ) ⊟ g(x)``), their weighted mean and spread plus the noise; a covariance the
  next points cannot factor stops the loop;
* **update** with some rows of a sample (all, or the groups a gate passed): ``H`` (chained with
  ``∂(x ⊞ δ)/∂δ`` for an error-state model that has it) or the sigma points through ``h``, the
  innovation through the sensor's residual, the gain (rows of uncorrected states zero), Joseph's
  covariance (the UKF's ``P − K S Kᵀ`` kept positive definite), the error folded into the state;
* **gate and reset** (:mod:`quadlib.engine.numerics`): each group's χ² test, and a group refused
  for longer than the sensor's ``reset_after_s`` widens ``P`` toward the sample and is used.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.engine.numerics import (
    block,
    gain_update,
    groups_rejected,
    lockout_cleared,
    lockout_expired,
    masked,
    picked,
    picked_rows,
    propagated,
    quadratic_form,
    rows_where,
    smoother_gain,
    weighted_mean,
    widened,
)
from quadlib.kernels.linalg import add_outer, inverse, positive_definite, product, times, upper_cholesky

# isort: off
# >>> the filter's kernels and flags: quadlib.engine.build writes this part for each filter
from quadlib.engine.defaults import (
    model_add_jacobian,
    model_G,
    model_g,
    model_input_noise,
    model_normalize,
    model_normalize_jacobian,
    model_Q,
    model_residual_x,
    model_state_add,
    sensor_H,
    sensor_h,
    sensor_mean,
    sensor_residual,
    sigma_difference,
    sigma_mean,
)

ERROR_STATE = G_IDENTITY = INPUT_NOISE = NORMALIZE = NORMALIZE_JACOBIAN = ADD_JACOBIAN = False
# <<<
# isort: on

# rows of the model's parameters, in the order of quadlib.engine.kernel.MODEL_ROLES
G_, JAC, Q_, INPUT, ADD, DIFF, ADD_JAC, NORM, NORM_JAC = range(9)


@njit(cache=True, inline="always")
def normalized(mp, x, P):
    """``normalize`` after a step (an additive model's ``P`` carried through its Jacobian)."""
    if not NORMALIZE:
        return x, P
    if NORMALIZE_JACOBIAN:
        J = model_normalize_jacobian(x, mp[NORM_JAC])
        P = product(product(J, P), J.T)
    return model_normalize(x, mp[NORM]), P


@njit(cache=True, inline="always")
def settle(mp, x, e, P):
    """The state after a correction ``e``: folded in (``x ⊞ e``, when ``e`` is not zero) or added, then
    :func:`normalized`."""
    if not ERROR_STATE:
        return normalized(mp, x + e, P)
    for i in range(e.shape[0]):
        if e[i] != 0.0:
            return normalized(mp, model_state_add(x, e, mp[ADD]), P)
    return normalized(mp, x, P)


@njit(cache=True, inline="always")
def step_noise(mp, u, dt, q_dt, Q, fixed_Q):
    """The step's process noise ``Q(Δt)`` (``Q`` itself when ``fixed_Q``) plus the input's, and the
    ``(q_dt, Q)`` to reuse."""
    if not fixed_Q and abs(dt - q_dt) > 1e-9 * dt:
        q_dt, Q = dt, model_Q(dt, mp[Q_])
    if INPUT_NOISE:
        added, extra = model_input_noise(u, dt, mp[INPUT])
        if added:
            return Q + extra, q_dt, Q
    return Q, q_dt, Q


@njit(cache=True, inline="always")
def ekf_predict(mp, x, P, u, dt, q_dt, Q, fixed_Q):
    """ModelEKF's predict: ``(x, P, q_dt, Q, healthy)`` (always healthy)."""
    Q_k, q_dt, Q = step_noise(mp, u, dt, q_dt, Q, fixed_Q)
    if G_IDENTITY:  # I P Iᵀ is P exactly
        P = P + Q_k
    else:
        P = propagated(model_G(x, u, dt, mp[JAC]), P, Q_k)
    x, P = normalized(mp, model_g(x, u, dt, mp[G_]), P)
    return x, P, q_dt, Q, True


@njit(cache=True, inline="always")
def residual_rows(s, z, z_hat, sp, rows, every):
    """The innovation of the rows ``rows`` (all of them when ``every``): the sensor's residual sees the
    full vectors with the other rows zero (:meth:`~quadlib.model.Sensor.subset`)."""
    if every:
        return sensor_residual(s, z, z_hat, sp)
    return picked(sensor_residual(s, masked(z, rows), masked(z_hat, rows), sp), rows)


@njit(cache=True, inline="always")
def ekf_correct(mp, sens, s, x, P, z, c, rows):
    """ModelEKF's update with the rows ``rows`` of sensor ``s``'s sample ``z``: the settled state,
    Joseph's ``P``, the innovation, ``S``, ``S⁻¹`` and whether it was healthy (always)."""
    kz = sens.dim_z[s]
    every = rows.shape[0] == kz
    H = sensor_H(s, x, c, sens.params[s, 1])
    if ERROR_STATE and ADD_JACOBIAN:
        H = product(H, model_add_jacobian(x, mp[ADD_JAC]))
    y = residual_rows(s, z, sensor_h(s, x, c, sens.params[s, 0]), sens.params[s, 2], rows, every)
    if every:
        e, P1, S, SI = gain_update(P, H, y, sens.R[s, :kz, :kz], sens.corrected[s])
    else:
        e, P1, S, SI = gain_update(P, picked_rows(H, rows), y, block(sens.R[s], rows), sens.corrected[s])
    x1, P1 = settle(mp, x, e, P1)
    return x1, P1, y, S, SI, True


@njit(cache=True)
def sigma_points(sig, x, P):
    """The sigma points (of the error, for an error-state model) and whether ``P`` was positive definite."""
    n = P.shape[0]
    U, ok = upper_cholesky(sig.scale * P)
    points = np.zeros((2 * n + 1, n))
    if ERROR_STATE:
        for k in range(n):
            points[k + 1], points[n + k + 1] = U[k], -U[k]
    else:
        points[0] = x
        minus_U = -U  # one array for the n rows' negatives
        for k in range(n):
            points[k + 1] = sigma_difference(x, minus_U[k], sig.params[0])
            points[n + k + 1] = sigma_difference(x, U[k], sig.params[0])
    return points, ok


@njit(cache=True, inline="always")
def point_state(mp, x, point):
    """The state a sigma point stands for."""
    if ERROR_STATE:
        return model_state_add(x, point, mp[ADD])
    return point


@njit(cache=True)
def ukf_predict(mp, sig, x, P, u, dt, q_dt, Q, fixed_Q):
    """ModelUKF's predict: ``(x, P, q_dt, Q, healthy)``."""
    Q_k, q_dt, Q = step_noise(mp, u, dt, q_dt, Q, fixed_Q)
    points, ok = sigma_points(sig, x, P)
    if not ok:
        return x, P, q_dt, Q, False
    stepped = np.empty_like(points)
    P_new = Q_k.copy()
    if ERROR_STATE:
        after = model_g(x, u, dt, mp[G_])
        for i in range(points.shape[0]):
            stepped[i] = model_residual_x(model_g(point_state(mp, x, points[i]), u, dt, mp[G_]), after, mp[DIFF])
        e = weighted_mean(stepped, sig.Wm)
        for i in range(points.shape[0]):
            d = stepped[i] - e
            add_outer(P_new, sig.Wc[i], d, d)
        healthy = upper_cholesky(sig.scale * P_new)[1]  # filterpy draws the next points from it
        x, P = settle(mp, after, e, P_new)
        return x, P, q_dt, Q, healthy
    for i in range(points.shape[0]):
        stepped[i] = model_g(points[i], u, dt, mp[G_])
    x_new = sigma_mean(stepped, sig.Wm, sig.params[1])
    for i in range(points.shape[0]):
        d = sigma_difference(stepped[i], x_new, sig.params[0])
        add_outer(P_new, sig.Wc[i], d, d)
    healthy = upper_cholesky(sig.scale * P_new)[1]
    x_new, P_new = normalized(mp, x_new, P_new)
    return x_new, P_new, q_dt, Q, healthy


@njit(cache=True)
def ukf_correct(mp, sens, sig, s, x, P, z, c, rows):
    """ModelUKF's update with the rows ``rows`` of sensor ``s``'s sample ``z``: the settled state,
    ``P``, the innovation, ``S``, ``S⁻¹`` and whether ``P`` gave sigma points."""
    kz, r = sens.dim_z[s], rows.shape[0]
    every = r == kz
    points, ok = sigma_points(sig, x, P)
    if not ok:
        return x, P, np.zeros(r), np.zeros((r, r)), np.zeros((r, r)), False
    hp, rp = sens.params[s, 0], sens.params[s, 2]
    M = points.shape[0]
    Z = np.zeros((M, kz))  # the other rows left zero (Sensor.subset)
    for i in range(M):
        z_i = sensor_h(s, point_state(mp, x, points[i]), c, hp)
        for a in rows:
            Z[i, a] = z_i[a]
    z_mean = sensor_mean(s, Z, sig.Wm, sens.params[s, 3])
    S = sens.R[s, :kz, :kz].copy() if every else block(sens.R[s], rows)
    Pxz = np.zeros((P.shape[0], r))
    for i in range(M):
        dz = residual_rows(s, Z[i], z_mean, rp, rows, every)
        add_outer(S, sig.Wc[i], dz, dz)
        add_outer(Pxz, sig.Wc[i], points[i] if ERROR_STATE else sigma_difference(points[i], x, sig.params[0]), dz)
    SI = np.full((1, 1), 1.0 / S[0, 0]) if r == 1 else inverse(S)
    K = product(Pxz, SI)
    y = residual_rows(s, z, z_mean, rp, rows, every)
    e = np.zeros(P.shape[0])
    for i in range(P.shape[0]):
        for j in range(r):
            e[i] += K[i, j] * y[j]
    P_new = positive_definite(P - product(K, product(S, K.T)))
    x_new, P_new = settle(mp, x, e, P_new)
    return x_new, P_new, y, S, SI, True


@njit(cache=True, inline="always")
def predict(mp, sig, x, P, u, dt, q_dt, Q, fixed_Q):
    """An EKF's predict when ``sig`` is None, else a UKF's (numba keeps one of the two)."""
    if sig is None:
        return ekf_predict(mp, x, P, u, dt, q_dt, Q, fixed_Q)
    return ukf_predict(mp, sig, x, P, u, dt, q_dt, Q, fixed_Q)


@njit(cache=True, inline="always")
def correct(mp, sens, sig, s, x, P, z, c, rows):
    """An EKF's update when ``sig`` is None, else a UKF's."""
    if sig is None:
        return ekf_correct(mp, sens, s, x, P, z, c, rows)
    return ukf_correct(mp, sens, sig, s, x, P, z, c, rows)


@njit(cache=True, inline="always")
def gated_update(mp, sens, sig, s, x, P, z, c, force, rejected, every_row):
    """One sample: ``(x, P, y, S, nis, used, healthy)``, the gate's verdict on each group in
    ``rejected``; groups in ``force`` pass it, and the groups that pass update on their own
    (``every_row``: ``0, 1, …``, at least the sample's length)."""
    kz = sens.dim_z[s]
    x1, P1, y, S, SI, healthy = correct(mp, sens, sig, s, x, P, z, c, every_row[:kz])
    if not healthy:
        rejected[:] = False
        return x, P, y, S, np.nan, False, False
    nis = quadratic_form(y, SI)
    groups_rejected(nis, S, y, sens.group[s, :kz], sens.gates[s], force, rejected)
    if not rejected.any():
        return x1, P1, y, S, nis, True, True
    keep = rows_where(sens.group[s, :kz], rejected, False)
    if keep.shape[0] == 0:
        return x, P, y, S, nis, False, True
    x2, P2, _, _, _, healthy = correct(mp, sens, sig, s, x, P, z, c, keep)  # the groups that passed
    return x2, P2, y, S, nis, True, healthy


@njit(cache=True)
def widened_toward(mp, sens, s, x, P, z, c, expired):
    """``P`` widened along the rows of the ``expired`` groups
    (:meth:`~quadlib.model_filter.ModelFilter.inflate_toward`): ``J = ∂h(x ⊞ δ)/∂δ`` by central
    differences, then :func:`~quadlib.engine.numerics.widened`."""
    kz, hp, rp = sens.dim_z[s], sens.params[s, 0], sens.params[s, 2]
    rows = rows_where(sens.group[s, :kz], expired, True)
    y = picked(sensor_residual(s, z, sensor_h(s, x, c, hp), rp), rows)
    n = P.shape[0]
    J = np.empty((rows.shape[0], n))
    for j in range(n):
        eps = 1e-6 * (1.0 + abs(math.sqrt(P[j, j])))
        d = np.zeros(n)
        d[j] = eps
        if ERROR_STATE:
            plus, minus = model_state_add(x, d, mp[ADD]), model_state_add(x, -d, mp[ADD])
        else:
            plus, minus = x + d, x - d
        J[:, j] = picked(sensor_residual(s, sensor_h(s, plus, c, hp), sensor_h(s, minus, c, hp), rp), rows) / (2 * eps)
    return widened(P, J, y)


@njit(cache=True)
def filter_pass(t, u, x0, P0, q_dt, Q, fixed_Q, mp, sens, samples, sig):
    """The forward pass over a log of times ``t (N,)`` and held inputs ``u (N, m)``, from ``x0``, ``P0``
    with ``Q = Q(q_dt)`` computed last (or fixed, ``fixed_Q``); an EKF's when ``sig`` is None, else a
    UKF's. Returns ``x (N, n)``, ``P (N, p, p)`` (NaN from a step where the UKF stopped), the last
    ``q_dt`` and ``Q``, and for each sensor and sample (padded like ``samples.z``) the innovation, ``S``,
    NIS (NaN where not applied), and whether it was used, rejected (any group) or reset."""
    N, n_sensors = t.shape[0], sens.dim_z.shape[0]
    K, k_max, g_max = samples.z.shape[1], samples.z.shape[2], sens.gates.shape[1]
    xs, Ps = np.full((N, x0.shape[0]), np.nan), np.full((N, P0.shape[0], P0.shape[0]), np.nan)
    ys, Ss = np.full((n_sensors, K, k_max), np.nan), np.full((n_sensors, K, k_max, k_max), np.nan)
    nis = np.full((n_sensors, K), np.nan)
    used, rejected, reset = np.zeros((n_sensors, K), np.bool_), np.zeros((n_sensors, K), np.bool_), np.zeros(
        (n_sensors, K), np.bool_)
    since = np.full((n_sensors, g_max), np.nan)  # when each group's lock-out began
    refused = np.zeros((n_sensors, g_max, k_max + 2))  # its whitened readings (add_refused)
    no_force, rej, expired = np.zeros(g_max, np.bool_), np.zeros(g_max, np.bool_), np.zeros(g_max, np.bool_)
    next_sample, every_row = np.zeros(n_sensors, np.int64), np.arange(k_max)
    x, P = x0.copy(), P0.copy()
    for k in range(N):
        if k:
            x, P, q_dt, Q, healthy = predict(mp, sig, x, P, u[k - 1], t[k] - t[k - 1], q_dt, Q, fixed_Q)
            if not healthy:
                return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset
        for s in range(n_sensors):
            kz, ng = sens.dim_z[s], sens.n_groups[s]
            r_s, e_s = rej[:ng], expired[:ng]
            while next_sample[s] < samples.count[s] and samples.step[s, next_sample[s]] == k:
                j = samples.use[s, next_sample[s]]
                next_sample[s] += 1
                z, c = samples.z[s, j, :kz], samples.c[s, j, :sens.dim_c[s]]
                x1, P1, y, S, nis_j, ok, healthy = gated_update(mp, sens, sig, s, x, P, z, c, no_force[:ng], r_s,
                                                             every_row)
                if healthy and r_s.any() and sens.reset_after_s[s] > 0.0:
                    lockout_expired(r_s, since[s, :ng], refused[s, :ng], samples.t[s, j], sens.reset_after_s[s],
                                    sens.agree_z[s], times(sens.whiten[s, :kz, :kz], y), sens.group[s, :kz], e_s)
                    if e_s.any():  # widen P along the locked-out groups and use them
                        P_wide = widened_toward(mp, sens, s, x, P, z, c, e_s)
                        x1, P1, y, S, nis_j, ok, healthy = gated_update(mp, sens, sig, s, x, P_wide, z, c, e_s,
                                                                     r_s, every_row)
                        reset[s, j] = True
                        for g in range(ng):
                            if e_s[g]:
                                since[s, g] = np.nan
                                refused[s, g] = 0.0
                if not healthy:
                    return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset
                if sens.gates[s, 0] > 0.0:
                    lockout_cleared(r_s, since[s, :ng], refused[s, :ng])
                x, P = x1, P1
                nis[s, j], used[s, j], rejected[s, j] = nis_j, ok, r_s.any()
                for a in range(kz):
                    ys[s, j, a] = y[a]
                    for b in range(kz):
                        Ss[s, j, a, b] = S[a, b]
        xs[k], Ps[k] = x, P
    return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset


@njit(cache=True)
def rts_pass(t, u, xs, Ps, mp):
    """:func:`~quadlib.replay.rts_smooth`'s backward pass over a forward run ``xs``, ``Ps`` with held
    inputs ``u``: the smoothed states and covariances."""
    xs_s, Ps_s = xs.copy(), Ps.copy()
    for i in range(t.shape[0] - 2, -1, -1):
        dt, x, P, u_i = t[i + 1] - t[i], xs[i], Ps[i], u[i]
        F = model_G(x, u_i, dt, mp[JAC])
        FP = product(F, P)
        prior_P = product(FP, F.T) + model_Q(dt, mp[Q_])
        if INPUT_NOISE:
            added, extra = model_input_noise(u_i, dt, mp[INPUT])
            if added:
                prior_P = prior_P + extra
        C = smoother_gain(FP, prior_P)
        x_prior = model_g(x, u_i, dt, mp[G_])
        if ERROR_STATE:
            x_s = model_state_add(x, times(C, model_residual_x(xs_s[i + 1], x_prior, mp[DIFF])), mp[ADD])
        else:
            x_s = x + times(C, xs_s[i + 1] - x_prior)
        if NORMALIZE:
            x_s = model_normalize(x_s, mp[NORM])
        xs_s[i] = x_s
        P_s = P + product(product(C, Ps_s[i + 1] - prior_P), C.T)
        Ps_s[i] = 0.5 * (P_s + P_s.T)
    return xs_s, Ps_s
