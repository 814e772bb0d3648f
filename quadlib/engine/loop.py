"""The compiled engine's one loop: :func:`~quadlib.replay.run_filter`'s schedule, gates and resets,
around the steps of an EKF (:mod:`quadlib.engine.ekf`) or a UKF (:mod:`quadlib.engine.ukf`).

At each step the predict, then each sensor's samples of that step in sensor order, one at a time:
the update with the whole sample; a χ² gate on each of the sensor's groups, the groups that pass
updating on their own; a group rejected for longer than the sensor's ``reset_after_s`` reset (``P``
widened toward the sample, as :meth:`~quadlib.model_filter.ModelFilter.inflate_toward` does) and
used. A UKF whose covariance the sigma points cannot factor stops the loop: the states from that
step on are NaN, and the caller hands the log to the readable loop, which raises there.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.engine.dispatch import measure, residual, state_add
from quadlib.engine.ekf import ADD, ekf_correct, ekf_predict
from quadlib.engine.ukf import ukf_correct, ukf_predict
from quadlib.kernels.linalg import add_refused, product, scatter_agrees, times

__all__ = ["filter_pass"]


@njit(cache=True, inline="always")
def _predict(m, sig, x, P, u, dt, q_dt, Q):
    """An EKF's predict when ``sig`` is None, else a UKF's (the branch is pruned when compiled)."""
    if sig is None:
        return ekf_predict(m, x, P, u, dt, q_dt, Q)
    return ukf_predict(m, sig, x, P, u, dt, q_dt, Q)


@njit(cache=True, inline="always")
def _correct(m, sens, sig, s, x, P, z, c, rows):
    """An EKF's update when ``sig`` is None, else a UKF's (the branch is pruned when compiled)."""
    if sig is None:
        return ekf_correct(m, sens, s, x, P, z, c, rows)
    return ukf_correct(m, sens, sig, s, x, P, z, c, rows)


@njit(cache=True)
def _groups_rejected(S, y, group, gates, force, rejected):
    """Which of a sample's several groups the gate rejects: each group's own ``yᵀ S⁻¹ y`` (kept out
    of the inlined update, which sensors with one group run)."""
    kz = y.shape[0]
    for g in range(rejected.shape[0]):
        rows = np.array([r for r in range(kz) if group[r] == g])
        y_g = y[rows]
        rejected[g] = not force[g] and y_g @ np.linalg.solve(S[rows][:, rows], y_g) > gates[g]


@njit(cache=True, inline="always")
def _update(m, sens, sig, s, x, P, z, c, force, every_row):
    """One sample: ``(x, P, y, S, nis, used, rejected groups, healthy)``; groups in ``force`` pass the
    gate; ``every_row`` is ``0, 1, …`` (at least the sample's length)."""
    kz, ng, group = sens.dim_z[s], sens.n_groups[s], sens.group[s]
    x1, P1, y, S, SI, healthy = _correct(m, sens, sig, s, x, P, z, c, every_row[:kz])
    rejected = np.zeros(ng, np.bool_)
    if not healthy:
        return x, P, y, S, np.nan, False, rejected, False
    nis = 0.0
    for i in range(kz):
        for j in range(kz):
            nis += y[i] * SI[i, j] * y[j]
    if sens.gates[s, 0] > 0.0:
        if ng == 1:
            rejected[0] = nis > sens.gates[s, 0] and not force[0]
        else:
            _groups_rejected(S, y, group[:kz], sens.gates[s], force, rejected)
    if not rejected.any():
        return x1, P1, y, S, nis, True, rejected, True
    keep = np.array([r for r in range(kz) if not rejected[group[r]]])
    if keep.shape[0] == 0:
        return x, P, y, S, nis, False, rejected, True
    x2, P2, _, _, _, healthy = _correct(m, sens, sig, s, x, P, z, c, keep)  # the groups that passed
    return x2, P2, y, S, nis, True, rejected, healthy


@njit(cache=True)
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
def filter_pass(t, u, x0, P0, q_dt, Q, model, sensors, samples, sigma):
    """The forward pass over a log of times ``t (N,)`` and held inputs ``u (N, m)``, from ``x0``, ``P0``
    with ``Q = Q(q_dt)`` computed last; an EKF's when ``sigma`` is None, else a UKF's (numba compiles
    the two apart). Returns ``x (N, n)``, ``P (N, p, p)`` (NaN from a step where the UKF stopped), the
    last ``q_dt`` and ``Q``, and for each sensor and sample (padded like ``samples.z``) the innovation, ``S``, NIS
    (NaN where not applied), and whether it was used, rejected (any group) or reset."""
    N, n_sensors = t.shape[0], sensors.dim_z.shape[0]
    K, k_max = samples.z.shape[1], samples.z.shape[2]
    xs, Ps = np.full((N, x0.shape[0]), np.nan), np.full((N, P0.shape[0], P0.shape[0]), np.nan)
    ys, Ss = np.full((n_sensors, K, k_max), np.nan), np.full((n_sensors, K, k_max, k_max), np.nan)
    nis = np.full((n_sensors, K), np.nan)
    used, rejected = np.zeros((n_sensors, K), np.bool_), np.zeros((n_sensors, K), np.bool_)
    reset = np.zeros((n_sensors, K), np.bool_)
    since = np.full((n_sensors, sensors.gates.shape[1]), np.nan)  # when each group's lock-out began
    refused = np.zeros((n_sensors, sensors.gates.shape[1], k_max + 2))  # its whitened readings (add_refused)
    no_force = np.zeros(sensors.gates.shape[1], np.bool_)
    next_sample = np.zeros(n_sensors, np.int64)
    every_row = np.arange(k_max)
    x, P = x0.copy(), P0.copy()
    for k in range(N):
        if k:
            x, P, q_dt, Q, healthy = _predict(model, sigma, x, P, u[k - 1], t[k] - t[k - 1], q_dt, Q)
            if not healthy:
                return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset
        for s in range(n_sensors):
            kz, ng = sensors.dim_z[s], sensors.n_groups[s]
            while next_sample[s] < samples.count[s] and samples.step[s, next_sample[s]] == k:
                j = samples.use[s, next_sample[s]]
                next_sample[s] += 1
                z, c = samples.z[s, j, :kz], samples.c[s, j, :sensors.dim_c[s]]
                x1, P1, y, S, nis_j, ok, rej, healthy = _update(model, sensors, sigma, s, x, P, z, c, no_force[:ng],
                                                                 every_row)
                if healthy and rej.any() and sensors.reset_after_s[s] > 0.0:
                    t_j = samples.t[s, j]
                    agreeing = not np.isnan(sensors.agree_z[s])
                    if agreeing:
                        add_refused(refused[s], times(sensors.whiten[s, :kz, :kz], y[:kz]), sensors.group[s, :kz], rej)
                    expired = np.zeros(ng, np.bool_)
                    for g in range(ng):
                        if rej[g]:
                            expired[g] = not np.isnan(since[s, g]) and t_j - since[s, g] >= sensors.reset_after_s[s]
                            if expired[g] and agreeing:
                                expired[g] = scatter_agrees(refused[s, g], float(np.sum(sensors.group[s, :kz] == g)),
                                                            sensors.agree_z[s])
                            if np.isnan(since[s, g]):
                                since[s, g] = t_j
                    if expired.any():  # widen P along the locked-out groups and use them
                        P_wide = _widened(model, sensors, s, x, P, z, c, expired)
                        x1, P1, y, S, nis_j, ok, rej, healthy = _update(model, sensors, sigma, s, x, P_wide, z, c,
                                                                        expired, every_row)
                        reset[s, j] = True
                        for g in range(ng):
                            if expired[g]:
                                since[s, g] = np.nan
                                refused[s, g] = 0.0
                if not healthy:
                    return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset
                if sensors.gates[s, 0] > 0.0:
                    for g in range(ng):
                        if not rej[g]:
                            since[s, g] = np.nan
                            refused[s, g] = 0.0
                x, P = x1, P1
                nis[s, j], used[s, j], rejected[s, j] = nis_j, ok, rej.any()
                for a in range(kz):
                    ys[s, j, a] = y[a]
                    for b in range(kz):
                        Ss[s, j, a, b] = S[a, b]
        xs[k], Ps[k] = x, P
    return xs, Ps, q_dt, Q, ys, Ss, nis, used, rejected, reset
