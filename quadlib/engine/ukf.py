"""The compiled UKF's steps: :class:`~quadlib.ModelUKF`'s predict and update, as
:func:`~quadlib.replay.run_filter` drives it, for the loop of :mod:`quadlib.engine.loop`.

Van der Merwe's sigma points (filterpy's ``MerweScaledSigmaPoints``) from ``U = chol((λ + n) P)``:
for an additive state ``x`` and ``x ⊟ ∓Uₖ`` (the filter's ``residual_x``, plain ``−`` by default);
for an error-state model the error's ``0`` and ``±Uₖ``, each added to the state with ``⊞``. Each step:

* **predict**: the points through ``g`` — an error-state model's as ``g(x ⊞ δ) ⊟ g(x)`` — their
  weighted mean (the filter's ``x_mean_fn``, or ``w X``) and spread plus ``Q(Δt)`` and the input's
  noise; the mean error folded into the state, ``normalize`` applied. A covariance the next points
  cannot factor stops the loop (filterpy raises there);
* **update** with some rows of a sample (all, or the groups a gate passed): the points measured
  through ``h`` (after ``⊞``), their mean (the sensor's ``mean``, or ``w Z``) and spread plus ``R``,
  the innovation through the sensor's residual, the gain from the points' cross-covariance,
  ``P − K S Kᵀ`` kept positive definite, the correction folded in.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.engine.dispatch import mean, measure, residual_x, state_add, transition
from quadlib.engine.ekf import ADD, DIFF, G_, normalized, residual_rows, settle, step_noise
from quadlib.kernels.linalg import add_outer, inverse, positive_definite, product, upper_cholesky

__all__ = ["ukf_correct", "ukf_predict"]


@njit(cache=True, inline="always")
def _difference(sig, a, b):
    """An additive state's ``a ⊟ b`` (the filter's ``residual_x``)."""
    if sig.kinds[0] < 0:
        return a - b
    return residual_x(sig.kinds[0], a, b, sig.params[0])


@njit(cache=True, inline="always")
def _points(m, sig, x, P):
    """The sigma points (of the error, for an error-state model) and whether ``P`` was positive definite."""
    n = P.shape[0]
    U, ok = upper_cholesky(sig.scale * P)
    points = np.zeros((2 * n + 1, n))
    if m.error_state:
        for k in range(n):
            points[k + 1], points[n + k + 1] = U[k], -U[k]
    else:
        points[0] = x
        minus_U = -U  # one array for the n rows' negatives
        for k in range(n):
            points[k + 1], points[n + k + 1] = _difference(sig, x, minus_U[k]), _difference(sig, x, U[k])
    return points, ok


@njit(cache=True, inline="always")
def _state(m, x, point):
    """The state a sigma point stands for."""
    if m.error_state:
        return state_add(m.kinds[ADD], x, point, m.params[ADD])
    return point


@njit(cache=True)
def ukf_predict(m, sig, x, P, u, dt, q_dt, Q):
    """ModelUKF's predict: ``(x, P, q_dt, Q, healthy)``."""
    k, p = m.kinds, m.params
    Q_k, q_dt, Q = step_noise(m, u, dt, q_dt, Q)
    points, ok = _points(m, sig, x, P)
    if not ok:
        return x, P, q_dt, Q, False
    stepped = np.empty_like(points)
    P_new = Q_k.copy()
    if m.error_state:
        after = transition(k[G_], x, u, dt, p[G_])
        for i in range(points.shape[0]):
            stepped[i] = residual_x(k[DIFF], transition(k[G_], _state(m, x, points[i]), u, dt, p[G_]), after, p[DIFF])
        e = mean(-1, stepped, sig.Wm, sig.params[1])
        for i in range(points.shape[0]):
            d = stepped[i] - e
            add_outer(P_new, sig.Wc[i], d, d)
        healthy = upper_cholesky(sig.scale * P_new)[1]  # filterpy draws the next points from it
        x, P = settle(m, after, e, P_new)
        return x, P, q_dt, Q, healthy
    for i in range(points.shape[0]):
        stepped[i] = transition(k[G_], points[i], u, dt, p[G_])
    x_new = mean(sig.kinds[1], stepped, sig.Wm, sig.params[1])
    for i in range(points.shape[0]):
        d = _difference(sig, stepped[i], x_new)
        add_outer(P_new, sig.Wc[i], d, d)
    healthy = upper_cholesky(sig.scale * P_new)[1]
    x_new, P_new = normalized(m, x_new, P_new)
    return x_new, P_new, q_dt, Q, healthy


@njit(cache=True)
def ukf_correct(m, sens, sig, s, x, P, z, c, rows):
    """ModelUKF's update with the rows ``rows`` of sensor ``s``'s sample ``z``: the settled state,
    ``P``, the innovation, ``S``, ``S⁻¹`` and whether ``P`` gave sigma points."""
    kz, r = sens.dim_z[s], rows.shape[0]
    every = r == kz
    points, ok = _points(m, sig, x, P)
    if not ok:
        return x, P, np.zeros(r), np.zeros((r, r)), np.zeros((r, r)), False
    h_kind, hp, r_kind, rp = sens.kinds[s, 0], sens.params[s, 0], sens.kinds[s, 2], sens.params[s, 2]
    M = points.shape[0]
    Z = np.zeros((M, kz))  # the other rows left zero (Sensor.subset)
    for i in range(M):
        z_i = measure(h_kind, _state(m, x, points[i]), c, hp)
        for a in rows:
            Z[i, a] = z_i[a]
    z_mean = mean(sens.kinds[s, 3], Z, sig.Wm, sens.params[s, 3])
    S = sens.R[s, :kz, :kz].copy() if every else np.ascontiguousarray(sens.R[s][rows][:, rows])
    Pxz = np.zeros((P.shape[0], r))
    for i in range(M):
        dz = residual_rows(r_kind, Z[i], z_mean, rp, rows, every)
        add_outer(S, sig.Wc[i], dz, dz)
        add_outer(Pxz, sig.Wc[i], points[i] if m.error_state else _difference(sig, points[i], x), dz)
    SI = np.full((1, 1), 1.0 / S[0, 0]) if r == 1 else inverse(S)
    K = product(Pxz, SI)
    y = residual_rows(r_kind, z, z_mean, rp, rows, every)
    e = np.zeros(P.shape[0])
    for i in range(P.shape[0]):
        for j in range(r):
            e[i] += K[i, j] * y[j]
    P_new = positive_definite(P - product(K, product(S, K.T)))
    x_new, P_new = settle(m, x, e, P_new)
    return x_new, P_new, y, S, SI, True
