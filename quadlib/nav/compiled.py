"""The inertial navigation filter's loops, compiled: what :func:`~quadlib.replay.run_filter` and
:func:`~quadlib.replay.rts_smooth` do with the INS of :func:`~quadlib.nav.ins.estimate_ins`, at C speed.

``estimate_ins(..., compiled=False)`` is the readable filter — :class:`~quadlib.ModelEKF` on
:func:`~quadlib.nav.ins.ins_model` with GPS, barometer and magnetometer heading, driven by
``run_filter`` — and chapter 17 builds it in view. It costs 250–370 µs a step, nearly all of it
the overhead of small numpy arrays, so the same steps are written here once more as plain loops
that numba compiles. :mod:`tests.nav.test_compiled` checks that both give the same states,
covariances and sensor traces to 1e-10, with gate rejections, resets, dropouts and the smoother.

The caller passes the updates as events — step, sensor (0 GPS, 1 barometer, 2 heading), sample —
in the order ``run_filter`` applies them (:func:`~quadlib.replay.compiled_schedule`). Each step:

* **predict** with the input block of the step before (NaN rows already held): the mean with the
  strapdown step, the covariance with the error Jacobian, ``Q(Δt)`` reused while ``Δt`` stays
  within 1e-9 of the step it was computed for; then the quaternion normalised;
* **updates**, each with its χ² gate (a threshold ``≤ 0``: none): GPS position and velocity gated
  as two groups, and a group rejected for ``reset_after_s`` reset as
  :meth:`~quadlib.model_filter.ModelFilter.inflate_toward` does (its covariance widened toward the
  fix, which is then used); the barometer's height; the magnetometer's heading, heading-only or
  tilt-aware (:func:`~quadlib.attitude.heading_sensor`), its gain masked for a consider update.
  The error is folded into the state (``q ⊗ exp(δθ)``, the rest added) and the quaternion normalised.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.compiled_kernels import (
    attitude_bias_jacobian,
    called_from_python,
    dcm,
    diverged,
    exp_rotvec,
    inverse,
    kalman_update,
    matrix,
    multiply,
    normalize,
    product,
    rate_matrix,
    rotvec,
    skew,
    wrap,
)

__all__: list[str] = []  # internal: ins.py is the interface

GPS, BARO, HEADING = 0, 1, 2


@njit(cache=True)
def _process_noise(sg, sa, sbg, sba, dt):
    """``Q(Δt)`` of :func:`~quadlib.nav.ins.ins_model`: velocity and position share one acceleration error."""
    Q = np.zeros((15, 15))
    for i in range(3):
        sa2 = sa[i] ** 2
        Q[i, i] = (sg * dt) ** 2
        Q[3 + i, 3 + i] = sa2 * dt**2
        Q[6 + i, 6 + i] = sa2 * dt**4 / 4.0
        Q[3 + i, 6 + i] = Q[6 + i, 3 + i] = sa2 * dt**3 / 2.0
        Q[9 + i, 9 + i] = sbg**2 * dt
        Q[12 + i, 12 + i] = sba**2 * dt
    return Q


@njit(cache=True)
def _step(x, u, dt, gravity_n):
    """The strapdown step (:mod:`quadlib.nav.ins`): ``R`` at the start of the step."""
    f = u[3:] - x[13:]
    a = dcm(x[:4]) @ f + gravity_n
    out = x.copy()
    out[:4] = multiply(x[:4], exp_rotvec((u[:3] - x[10:13]) * dt))
    out[4:7] = x[4:7] + a * dt
    out[7:10] = x[7:10] + x[4:7] * dt + 0.5 * a * dt * dt
    return out


@njit(cache=True)
def _error_jacobian(x, u, dt):
    """``∂δx⁺/∂δx`` (15 × 15) of the step (:mod:`quadlib.nav.ins`)."""
    R = dcm(x[:4])
    G = attitude_bias_jacobian((u[:3] - x[10:13]) * dt, dt)
    F = np.eye(15)
    F[0:3, 0:3], F[0:3, 9:12] = G[:3, :3], G[:3, 3:]
    dv_dtheta, dv_dba = product(-dt * R, skew(u[3:] - x[13:])), -dt * R
    F[3:6, 0:3], F[3:6, 12:15] = dv_dtheta, dv_dba
    F[6:9, 0:3], F[6:9, 12:15] = 0.5 * dt * dv_dtheta, 0.5 * dt * dv_dba
    for i in range(3):
        F[6 + i, 3 + i] = dt
    return F


@njit(cache=True)
def _settled(x, e):
    """The error folded into the state (when there is one), the quaternion normalised."""
    out = x.copy()
    if np.any(e != 0.0):
        out[:4] = multiply(x[:4], exp_rotvec(e[:3]))
        out[4:] = x[4:] + e[3:]
    out[:4] = normalize(out[:4])
    return out


@njit(cache=True)
def _heading(x, m_b, tilt_aware):
    """The heading of the body field ``m_b`` [rad] and its Jacobian over the error state ``(1, 15)``
    (:func:`~quadlib.attitude.heading_sensor`), chained through ``∂q/∂δθ = ½ Ξ(q)``."""
    R = dcm(x[:4])
    m_n = R @ m_b
    if tilt_aware:
        d_psi = matrix(1, 3, (-m_n[1], m_n[0], 0.0)) / (m_n[0] ** 2 + m_n[1] ** 2)
        row = product(product(-d_psi, R), skew(m_b))
    else:
        row = R[2:3].copy()
    Xi = rate_matrix(x[:4])
    H = np.zeros((1, 15))
    H[:, :3] = product(product(row, 2.0 * Xi.T), 0.5 * Xi)
    return math.atan2(m_n[1], m_n[0]), H


@njit(cache=True)
def _gated_update(P, H, y, R, corrected, group, gates, force):
    """:meth:`~quadlib.model_filter.ModelFilter.update_unchecked` for one sample: component ``i`` in
    group ``group[i]``, each group's NIS against ``gates[g]`` (``≤ 0``: not gated) unless ``force[g]``,
    and the update with the components whose group passed.

    Returns the error, ``P``, the whole sample's NIS and ``S``, which groups were rejected, and
    whether any component was used."""
    m, n_groups = y.shape[0], gates.shape[0]
    S = product(H, product(P, H.T)) + R
    SI = inverse(S)
    nis = 0.0
    for i in range(m):
        for j in range(m):
            nis += y[i] * SI[i, j] * y[j]
    rejected = np.zeros(n_groups, np.bool_)
    for g in range(n_groups):
        if gates[g] > 0.0 and not force[g]:
            if n_groups == 1:
                rejected[g] = nis > gates[g]
            else:
                rows = np.flatnonzero(group == g)
                y_g = y[rows]
                rejected[g] = y_g @ np.linalg.solve(S[rows][:, rows], y_g) > gates[g]
    keep = np.flatnonzero(~rejected[group])
    if keep.size == 0:
        return np.zeros(P.shape[0]), P, nis, S, rejected, False
    if keep.size < m:
        H, y, R = H[keep], y[keep], R[keep][:, keep]
    e, P_new, _, _, _ = kalman_update(P, H, y, R, corrected, 0.0)
    return e, P_new, nis, S, rejected, True


@njit(cache=True)
def _inflated(x, P, z, index, rows):
    """:meth:`~quadlib.model_filter.ModelFilter.inflate_toward` for GPS components ``rows``, which
    measure states ``index[rows]`` directly: the same central differences through ``x ⊞ δ`` and the
    same pseudo-inverse."""
    n, r = P.shape[0], rows.shape[0]
    y = np.empty(r)
    J = np.zeros((r, n))
    for a in range(r):
        s = index[rows[a]]
        y[a] = z[rows[a]] - x[s]
        for j in range(n):
            eps = 1e-6 * (1.0 + abs(math.sqrt(P[j, j])))
            d = eps if j == s - 1 else 0.0  # x ⊞ δ moves state s (≥ 4) by δ[s − 1]
            J[a, j] = ((x[s] + d) - (x[s] + -d)) / (2 * eps)
    J_pinv = np.linalg.pinv(J, 1e-6)
    P = P + (J_pinv @ np.diag(y**2)) @ J_pinv.T
    return 0.5 * (P + P.T)


@njit(cache=True)
def _traces(k, m):
    """A sensor's trace: innovation, S, NIS, used, rejected, reset (NaN / False where not applied)."""
    return (np.full((k, m), np.nan), np.full((k, m, m), np.nan), np.full(k, np.nan), np.zeros(k, np.bool_),
            np.zeros(k, np.bool_), np.zeros(k, np.bool_))


@called_from_python
@njit(cache=True)
def ins_pass(t, u, event_step, event_sensor, event_sample, x0, P0, dt0, sg, sa, sbg, sba, gravity_n,
             gps_t, gps_z, gps_index, gps_group, gps_gates, R_gps, reset_after_s,
             baro_z, baro_gate, R_baro, heading_z, heading_context, heading_gate, R_heading, heading_corrected,
             tilt_aware):
    """The forward pass: ``u`` with its NaN rows already held (:func:`~quadlib.replay.held_inputs`),
    the updates as events. GPS component ``i`` measures state ``gps_index[i]`` and is gated in group
    ``gps_group[i]``; ``reset_after_s ≤ 0``: no reset. From the step where the estimate became
    non-finite on, ``x`` and ``P`` are NaN.

    Returns ``x (N, 16)``, ``P (N, 15, 15)`` and the traces of GPS, barometer and heading
    (:func:`_traces`)."""
    n = t.shape[0]
    xs, Ps = np.empty((n, 16)), np.empty((n, 15, 15))
    gps, baro, heading = _traces(*gps_z.shape), _traces(baro_z.shape[0], 1), _traces(heading_z.shape[0], 1)
    m_gps, n_groups = gps_z.shape[1], gps_gates.shape[0]
    H_gps = np.zeros((m_gps, 15))
    for i in range(m_gps):
        H_gps[i, gps_index[i] - 1] = 1.0  # state s ≥ 4 is error s − 1
    H_baro = np.zeros((1, 15))
    H_baro[0, 8] = -1.0
    every, one = np.ones(15, np.bool_), np.zeros(1, np.int64)
    no_force, single = np.zeros(n_groups, np.bool_), np.zeros(1, np.bool_)
    locked_since = np.full(n_groups, np.nan)
    x, P = x0.copy(), P0.copy()
    q_dt, Q = dt0, _process_noise(sg, sa, sbg, sba, dt0)
    e = 0
    for k in range(n):
        if k:
            dt = t[k] - t[k - 1]
            if abs(dt - q_dt) > 1e-9 * dt:
                q_dt, Q = dt, _process_noise(sg, sa, sbg, sba, dt)
            F = _error_jacobian(x, u[k - 1], dt)
            x = _step(x, u[k - 1], dt, gravity_n)
            x[:4] = normalize(x[:4])
            P = product(product(F, P), F.T) + Q
        while e < event_step.shape[0] and event_step[e] == k:
            if diverged(x, P):  # the caller hands the log to run_filter, which names the step
                xs[k:], Ps[k:] = np.nan, np.nan
                return xs, Ps, gps, baro, heading
            j = event_sample[e]
            if event_sensor[e] == GPS:
                y = gps_z[j] - x[gps_index]
                dx, P_new, nis, S, rejected, used = _gated_update(P, H_gps, y, R_gps, every, gps_group, gps_gates,
                                                                  no_force)
                if rejected.any() and reset_after_s > 0.0:  # run_filter's timed reset
                    expired = rejected & (gps_t[j] - locked_since >= reset_after_s)  # NaN: not locked yet
                    locked_since[rejected & np.isnan(locked_since)] = gps_t[j]
                    if expired.any():
                        P = _inflated(x, P, gps_z[j], gps_index, np.flatnonzero(expired[gps_group]))
                        dx, P_new, nis, S, rejected, used = _gated_update(P, H_gps, y, R_gps, every, gps_group,
                                                                          gps_gates, expired)
                        gps[5][j] = True
                        locked_since[expired] = np.nan
                if gps_gates[0] > 0.0:
                    locked_since[~rejected] = np.nan
                trace = gps
            elif event_sensor[e] == BARO:
                y = baro_z[j] + x[9:10]
                dx, P_new, nis, S, rejected, used = _gated_update(P, H_baro, y, R_baro, every, one,
                                                                  np.full(1, baro_gate), single)
                trace = baro
            else:
                psi, H = _heading(x, heading_context[j], tilt_aware)
                y = np.array([wrap(heading_z[j, 0] - psi)])
                dx, P_new, nis, S, rejected, used = _gated_update(P, H, y, R_heading, heading_corrected, one,
                                                                  np.full(1, heading_gate), single)
                trace = heading
            trace[0][j], trace[1][j], trace[2][j], trace[3][j], trace[4][j] = y, S, nis, used, rejected.any()
            if used:
                x, P = _settled(x, dx), P_new
            e += 1
        xs[k], Ps[k] = x, P
    return xs, Ps, gps, baro, heading


@called_from_python
@njit(cache=True)
def ins_rts_pass(t, u, xs, Ps, sg, sa, sbg, sba, gravity_n):
    """The Rauch–Tung–Striebel backward pass of :func:`~quadlib.replay.rts_smooth` for the INS:
    ``u`` with NaN rows already held."""
    n = t.shape[0]
    xs_s, Ps_s = xs.copy(), Ps.copy()
    for k in range(n - 2, -1, -1):
        dt = t[k + 1] - t[k]
        x, P = xs[k], Ps[k]
        F = _error_jacobian(x, u[k], dt)
        prior_P = product(product(F, P), F.T) + _process_noise(sg, sa, sbg, sba, dt)
        C = np.linalg.solve(prior_P, F @ P).T
        prior = _step(x, u[k], dt, gravity_n)
        # xs_s[k+1] ⊟ prior: the rotation vector of q_prior⁻¹ ⊗ q_s, and plain differences
        diff = np.empty(15)
        q = prior[:4]
        diff[:3] = rotvec(multiply(np.array([q[0], -q[1], -q[2], -q[3]]), xs_s[k + 1, :4]))
        diff[3:] = xs_s[k + 1, 4:] - prior[4:]
        delta = C @ diff
        x_s = x.copy()
        x_s[:4] = normalize(multiply(x[:4], exp_rotvec(delta[:3])))
        x_s[4:] = x[4:] + delta[3:]
        xs_s[k] = x_s
        P_s = P + (C @ (Ps_s[k + 1] - prior_P)) @ C.T
        Ps_s[k] = 0.5 * (P_s + P_s.T)
    return xs_s, Ps_s
