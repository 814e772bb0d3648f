"""The compiled engine: one EKF loop and one RTS backward pass, for every model of :mod:`quadlib.kernels`.

:func:`~quadlib.replay.run_filter` with :class:`~quadlib.ModelEKF` is the readable filter; it costs
tens to hundreds of µs a sample, nearly all of it the overhead of small numpy arrays. This module
runs the same steps over a whole log in one numba loop, calling the model's and the sensors' own
kernels (through :mod:`quadlib.engine.dispatch`), so both compute with one implementation of the
maths; ``tests/engine/test_equality.py`` holds them equal to 1e-10. The caller
(:mod:`quadlib.engine.runner`) packs the filter, its sensors and the log's schedule into the three
records below. Each step, as ``run_filter`` does it:

* **predict** with the input of the step before (NaN rows already held): ``G`` at the previous
  state, ``Q(Δt)`` reused while ``Δt`` stays within 1e-9 of the step it was computed for, plus the
  input's noise, the mean through ``g``, ``P ← G P Gᵀ + Q``, then ``normalize`` (carrying ``P``
  through its Jacobian for an additive model that has one);
* **updates**, one event at a time in ``run_filter``'s order: ``H`` (chained with ``∂(x ⊞ δ)/∂δ``
  for an error-state model that has it), the innovation through the sensor's residual, ``S``, the
  gain with the rows of uncorrected states zero (a consider update), Joseph's covariance; a χ² gate
  on each of the sensor's groups, the groups that pass updating on their own; a group rejected for
  longer than the sensor's ``reset_after_s`` reset (``P`` widened toward the sample, as
  :meth:`~quadlib.model_filter.ModelFilter.inflate_toward` does) and used; the error folded into the
  state (``x ⊞ δx``, or added) and ``normalize`` applied.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from quadlib.compiled_kernels import inverse, product
from quadlib.engine.dispatch import (
    IDENTITY,
    add_jacobian,
    input_noise,
    jacobian,
    measure,
    measurement_jacobian,
    normalize,
    normalize_jacobian,
    process_noise,
    residual,
    residual_x,
    state_add,
    transition,
)

__all__ = ["ModelArrays", "Samples", "SensorArrays", "ekf_pass", "rts_pass"]

# rows of ModelArrays, in the order of quadlib.engine.kernel.MODEL_ROLES
G_, JAC, Q_, INPUT, ADD, DIFF, ADD_JAC, NORM, NORM_JAC = range(9)


class ModelArrays(NamedTuple):
    """A model: ``kinds[r]`` the number of role ``r``'s kernel in its table (``-1``: unused), ``params[r]``
    its parameters (padded), ``error_state`` whether ``P`` is over an error ``δx``."""

    kinds: np.ndarray
    params: np.ndarray
    error_state: bool


class SensorArrays(NamedTuple):
    """The sensors, one row each: kernels of ``h``, ``H`` and the residual (``kinds (S, 3)``, ``-1``
    residual: ``z − ẑ``) and their ``params (S, 3, m)``; ``dim_z``, ``dim_c``; ``R (S, k, k)``; each
    row's group (``group (S, k)``) and ``n_groups``; the χ² threshold of each group (``gates (S, g)``,
    ``≤ 0``: not gated); ``reset_after_s`` (``≤ 0``: never); ``corrected (S, p)``, the gain's rows kept."""

    kinds: np.ndarray
    params: np.ndarray
    dim_z: np.ndarray
    dim_c: np.ndarray
    R: np.ndarray
    group: np.ndarray
    n_groups: np.ndarray
    gates: np.ndarray
    reset_after_s: np.ndarray
    corrected: np.ndarray


class Samples(NamedTuple):
    """Each sensor's samples, one row of each array per sensor (padded): times ``t (S, K)``, values
    ``z (S, K, k)`` and contexts ``c (S, K, c)``; and the ``count[s]`` samples it applies, in order —
    sample ``use[s, i]`` after the predict of step ``step[s, i]`` (missing and repeated ones left out)."""

    t: np.ndarray
    z: np.ndarray
    c: np.ndarray
    use: np.ndarray
    step: np.ndarray
    count: np.ndarray


@njit(cache=True, inline="always")
def _times(A, v):
    """``A v`` as plain loops."""
    out = np.zeros(A.shape[0])
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            out[i] += A[i, j] * v[j]
    return out


@njit(cache=True, inline="always")
def _normalized(m, x, P):
    """``normalize`` after a step (an additive model's ``P`` carried through its Jacobian)."""
    k, p = m.kinds, m.params
    if k[NORM] < 0:
        return x, P
    if not m.error_state and k[NORM_JAC] >= 0:
        J = normalize_jacobian(k[NORM_JAC], x, p[NORM_JAC])
        P = product(product(J, P), J.T)
    return normalize(k[NORM], x, p[NORM]), P


@njit(cache=True, inline="always")
def _settle(m, x, e, P):
    """The state after a correction ``e``: folded in (``x ⊞ e``, when ``e`` is not zero) or added, then
    :func:`_normalized`."""
    if not m.error_state:
        return _normalized(m, x + e, P)
    if np.any(e != 0.0):
        x = state_add(m.kinds[ADD], x, e, m.params[ADD])
    return _normalized(m, x, P)


@njit(cache=True, inline="always")
def _propagated(F, P, Q):
    """``F P Fᵀ + Q``, symmetric: the upper triangle computed, the lower mirrored."""
    n = P.shape[0]
    FP = product(F, P)
    out = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            acc = 0.0
            for m in range(n):
                acc += FP[i, m] * F[j, m]
            out[i, j] = acc + Q[i, j]
            out[j, i] = out[i, j]
    return out


@njit(cache=True, inline="always")
def _predict(m, x, P, u, dt, q_dt, Q):
    k, p = m.kinds, m.params
    if abs(dt - q_dt) > 1e-9 * dt:
        q_dt, Q = dt, process_noise(k[Q_], dt, p[Q_])
    Q_k = Q
    if k[INPUT] >= 0:
        added, extra = input_noise(k[INPUT], u, dt, p[INPUT])
        if added:
            Q_k = Q + extra
    if k[JAC] == IDENTITY:  # I P Iᵀ is P exactly
        P = P + Q_k
    else:
        P = _propagated(jacobian(k[JAC], x, u, dt, p[JAC]), P, Q_k)
    x, P = _normalized(m, transition(k[G_], x, u, dt, p[G_]), P)
    return x, P, q_dt, Q


@njit(cache=True, inline="always")
def _linearized(m, sens, s, x, c):
    """``H`` over ``P``'s coordinates, and ``ẑ``."""
    H = measurement_jacobian(sens.kinds[s, 1], x, c, sens.params[s, 1])
    if m.error_state and m.kinds[ADD_JAC] >= 0:
        H = product(H, add_jacobian(m.kinds[ADD_JAC], x, m.params[ADD_JAC]))
    return H, measure(sens.kinds[s, 0], x, c, sens.params[s, 0])


@njit(cache=True, inline="always")
def _correct(m, x, P, H, y, R, corrected):
    """ModelEKF's update with the innovation ``y``: the settled state, Joseph's ``P``, ``S`` and ``S⁻¹``
    (the gain's rows of uncorrected states zero)."""
    n, k = P.shape[0], y.shape[0]
    PHT = np.zeros((n, k))
    for i in range(n):
        for m_ in range(n):
            a = P[i, m_]
            for j in range(k):
                PHT[i, j] += a * H[j, m_]
    S = np.empty((k, k))
    for i in range(k):
        for j in range(k):
            acc = R[i, j]
            for m_ in range(n):
                acc += H[i, m_] * PHT[m_, j]
            S[i, j] = acc
    SI = np.array([[1.0 / S[0, 0]]]) if k == 1 else inverse(S)
    K = np.zeros((n, k))
    e = np.zeros(n)
    for i in range(n):
        if corrected[i]:
            for a in range(k):
                PHT_ia = PHT[i, a]
                for j in range(k):
                    K[i, j] += PHT_ia * SI[a, j]
            for j in range(k):
                e[i] += K[i, j] * y[j]
    A = np.empty((n, n))  # I − K H
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for a in range(k):
                acc += K[i, a] * H[a, j]
            A[i, j] = (1.0 if i == j else 0.0) - acc
    AP, KR = product(A, P), product(K, R)
    P_new = np.empty((n, n))
    for i in range(n):  # Joseph's form (I − K H) P (I − K H)ᵀ + K R Kᵀ, symmetric: the upper triangle
        for j in range(i, n):
            acc = 0.0
            for m_ in range(n):
                acc += AP[i, m_] * A[j, m_]
            acc2 = 0.0
            for b in range(k):
                acc2 += KR[i, b] * K[j, b]
            P_new[i, j] = acc + acc2
            P_new[j, i] = P_new[i, j]
    x_new, P_new = _settle(m, x, e, P_new)
    return x_new, P_new, S, SI


@njit(cache=True, inline="always")
def _update(m, sens, s, x, P, z, c, force):
    """One sample: ``(x, P, y, S, nis, used, rejected groups)``; groups in ``force`` pass the gate."""
    kz, ng, kind, rp = sens.dim_z[s], sens.n_groups[s], sens.kinds[s, 2], sens.params[s, 2]
    R, group = sens.R[s, :kz, :kz], sens.group[s]
    H, z_hat = _linearized(m, sens, s, x, c)
    y = residual(kind, z, z_hat, rp)
    x1, P1, S, SI = _correct(m, x, P, H, y, R, sens.corrected[s])
    nis = 0.0
    for i in range(kz):
        for j in range(kz):
            nis += y[i] * SI[i, j] * y[j]
    rejected = np.zeros(ng, np.bool_)
    if sens.gates[s, 0] > 0.0:
        if ng == 1:
            rejected[0] = nis > sens.gates[s, 0] and not force[0]
        else:
            for g in range(ng):
                rows = np.array([r for r in range(kz) if group[r] == g])
                y_g = y[rows]
                rejected[g] = not force[g] and y_g @ np.linalg.solve(S[rows][:, rows], y_g) > sens.gates[s, g]
    if not rejected.any():
        return x1, P1, y, S, nis, True, rejected
    keep = np.array([r for r in range(kz) if not rejected[group[r]]])
    if keep.shape[0] == 0:
        return x, P, y, S, nis, False, rejected
    if kind < 0:  # the groups that passed update on their own (Sensor.subset)
        y_keep = z[keep] - z_hat[keep]
    else:
        z_in, z_hat_in = np.zeros(kz), np.zeros(kz)
        z_in[keep], z_hat_in[keep] = z[keep], z_hat[keep]
        y_keep = residual(kind, z_in, z_hat_in, rp)[keep]
    x2, P2, _, _ = _correct(m, x, P, np.ascontiguousarray(H[keep]), y_keep, R[keep][:, keep], sens.corrected[s])
    return x2, P2, y, S, nis, True, rejected


@njit(cache=True, inline="always")
def _widened(m, sens, s, x, P, z, c, expired):
    """``P`` widened along the rows of the ``expired`` groups
    (:meth:`~quadlib.model_filter.ModelFilter.inflate_toward`)."""
    kz, h_kind, hp, r_kind, rp = sens.dim_z[s], sens.kinds[s, 0], sens.params[s, 0], sens.kinds[s, 2], sens.params[s, 2]
    rows = np.array([r for r in range(kz) if expired[sens.group[s, r]]])
    y = residual(r_kind, z, measure(h_kind, x, c, hp), rp)[rows]
    n = P.shape[0]
    J = np.empty((rows.shape[0], n))
    for j in range(n):
        eps = 1e-6 * (1.0 + abs(math.sqrt(P[j, j])))
        d = np.zeros(n)
        d[j] = eps
        if m.error_state:
            plus = state_add(m.kinds[ADD], x, d, m.params[ADD])
            minus = state_add(m.kinds[ADD], x, -d, m.params[ADD])
        else:
            plus, minus = x + d, x - d
        J[:, j] = residual(r_kind, measure(h_kind, plus, c, hp), measure(h_kind, minus, c, hp), rp)[rows] / (2 * eps)
    J_pinv = np.linalg.pinv(J, rcond=1e-6)  # directions the sensor cannot see (below the noise) stay out
    P = P + product(product(J_pinv, np.diag(y**2)), J_pinv.T)
    return 0.5 * (P + P.T)


@njit(cache=True)
def ekf_pass(t, u, x0, P0, q_dt, Q, model, sensors, samples):
    """The forward pass over a log of times ``t (N,)`` and held inputs ``u (N, m)``, from ``x0``, ``P0``
    with ``Q = Q(q_dt)`` computed last. At each step the predict, then each sensor's samples of that
    step in sensor order (:func:`~quadlib.replay.run_filter`'s order). Returns ``x (N, n)``,
    ``P (N, p, p)``, the last ``q_dt`` and ``Q``, and for each sensor and sample (padded like
    ``samples.z``) the innovation, ``S``, NIS (NaN where not applied), and whether it was used,
    rejected (any group) or reset."""
    N, n_sensors = t.shape[0], sensors.dim_z.shape[0]
    K, k_max = samples.z.shape[1], samples.z.shape[2]
    xs, Ps = np.empty((N, x0.shape[0])), np.empty((N, P0.shape[0], P0.shape[0]))
    ys, Ss = np.full((n_sensors, K, k_max), np.nan), np.full((n_sensors, K, k_max, k_max), np.nan)
    nis = np.full((n_sensors, K), np.nan)
    used, rejected = np.zeros((n_sensors, K), np.bool_), np.zeros((n_sensors, K), np.bool_)
    reset = np.zeros((n_sensors, K), np.bool_)
    since = np.full((n_sensors, sensors.gates.shape[1]), np.nan)  # when each group's lock-out began
    no_force = np.zeros(sensors.gates.shape[1], np.bool_)
    next_sample = np.zeros(n_sensors, np.int64)
    x, P = x0.copy(), P0.copy()
    for k in range(N):
        if k:
            x, P, q_dt, Q = _predict(model, x, P, u[k - 1], t[k] - t[k - 1], q_dt, Q)
        for s in range(n_sensors):
            kz, ng = sensors.dim_z[s], sensors.n_groups[s]
            while next_sample[s] < samples.count[s] and samples.step[s, next_sample[s]] == k:
                j = samples.use[s, next_sample[s]]
                next_sample[s] += 1
                z, c = samples.z[s, j, :kz], samples.c[s, j, :sensors.dim_c[s]]
                x1, P1, y, S, nis_j, ok, rej = _update(model, sensors, s, x, P, z, c, no_force[:ng])
                if rej.any() and sensors.reset_after_s[s] > 0.0:
                    t_j = samples.t[s, j]
                    expired = np.zeros(ng, np.bool_)
                    for g in range(ng):
                        if rej[g]:
                            expired[g] = not np.isnan(since[s, g]) and t_j - since[s, g] >= sensors.reset_after_s[s]
                            if np.isnan(since[s, g]):
                                since[s, g] = t_j
                    if expired.any():  # widen P along the locked-out groups and use them
                        P_wide = _widened(model, sensors, s, x, P, z, c, expired)
                        x1, P1, y, S, nis_j, ok, rej = _update(model, sensors, s, x, P_wide, z, c, expired)
                        reset[s, j] = True
                        for g in range(ng):
                            if expired[g]:
                                since[s, g] = np.nan
                if sensors.gates[s, 0] > 0.0:
                    for g in range(ng):
                        if not rej[g]:
                            since[s, g] = np.nan
                x, P = x1, P1
                nis[s, j], used[s, j], rejected[s, j] = nis_j, ok, rej.any()
                for a in range(kz):
                    ys[s, j, a] = y[a]
                    for b in range(kz):
                        Ss[s, j, a, b] = S[a, b]
        xs[k], Ps[k] = x, P
    return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset


@njit(cache=True)
def rts_pass(t, u, xs, Ps, model):
    """:func:`~quadlib.replay.rts_smooth`'s backward pass over a forward run ``xs``, ``Ps`` with held
    inputs ``u``: the smoothed states and covariances."""
    k, p = model.kinds, model.params
    xs_s, Ps_s = xs.copy(), Ps.copy()
    for i in range(t.shape[0] - 2, -1, -1):
        dt, x, P, u_i = t[i + 1] - t[i], xs[i], Ps[i], u[i]
        F = jacobian(k[JAC], x, u_i, dt, p[JAC])
        FP = product(F, P)
        prior_P = product(FP, F.T) + process_noise(k[Q_], dt, p[Q_])
        if k[INPUT] >= 0:
            added, extra = input_noise(k[INPUT], u_i, dt, p[INPUT])
            if added:
                prior_P = prior_P + extra
        C = np.ascontiguousarray(np.linalg.solve(prior_P, FP).T)  # P Fᵀ (P⁻)⁻¹, P⁻ symmetric
        x_prior = transition(k[G_], x, u_i, dt, p[G_])
        if model.error_state:
            x_s = state_add(k[ADD], x, _times(C, residual_x(k[DIFF], xs_s[i + 1], x_prior, p[DIFF])), p[ADD])
        else:
            x_s = x + _times(C, xs_s[i + 1] - x_prior)
        if k[NORM] >= 0:
            x_s = normalize(k[NORM], x_s, p[NORM])
        xs_s[i] = x_s
        P_s = P + product(product(C, Ps_s[i + 1] - prior_P), C.T)
        Ps_s[i] = 0.5 * (P_s + P_s.T)
    return xs_s, Ps_s
