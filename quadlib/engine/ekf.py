"""The compiled engine's records, the EKF's steps and the RTS backward pass.

:func:`~quadlib.replay.run_filter` with :class:`~quadlib.ModelEKF` is the readable filter; it costs
tens to hundreds of µs a sample, nearly all of it the overhead of small numpy arrays. The engine
runs the same steps over a whole log in one numba loop (:func:`quadlib.engine.loop.filter_pass`),
calling the model's and the sensors' own kernels (through :mod:`quadlib.engine.dispatch`), so both
compute with one implementation of the maths; ``tests/engine/test_ekf.py`` holds them equal to
1e-10. The caller (:mod:`quadlib.engine.runner`) packs the filter, its sensors and the log's
schedule into the records below. The EKF's steps, as ``run_filter`` does them:

* **predict** with the input of the step before (NaN rows already held): ``G`` at the previous
  state, ``Q(Δt)`` reused while ``Δt`` stays within 1e-9 of the step it was computed for, plus the
  input's noise, the mean through ``g``, ``P ← G P Gᵀ + Q``, then ``normalize`` (carrying ``P``
  through its Jacobian for an additive model that has one);
* **update** with some rows of a sample (all, or the groups a gate passed): ``H`` (chained with
  ``∂(x ⊞ δ)/∂δ`` for an error-state model that has it), the innovation through the sensor's
  residual, ``S``, the gain with the rows of uncorrected states zero (a consider update), Joseph's
  covariance, the error folded into the state (``x ⊞ δx``, or added) and ``normalize`` applied.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

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
from quadlib.kernels.linalg import inverse, product, times

__all__ = ["ModelArrays", "Samples", "SensorArrays", "SigmaArrays", "ekf_correct", "ekf_predict", "rts_pass"]

# rows of ModelArrays, in the order of quadlib.engine.kernel.MODEL_ROLES
G_, JAC, Q_, INPUT, ADD, DIFF, ADD_JAC, NORM, NORM_JAC = range(9)


class ModelArrays(NamedTuple):
    """A model: ``kinds[r]`` the number of role ``r``'s kernel in its table (``-1``: unused), ``params[r]``
    its parameters (padded), ``error_state`` whether ``P`` is over an error ``δx``."""

    kinds: np.ndarray
    params: np.ndarray
    error_state: bool


class SensorArrays(NamedTuple):
    """The sensors, one row each: kernels of ``h``, ``H``, the residual and the mean (``kinds (S, 4)``,
    ``-1``: unused, or ``z − ẑ`` and ``w Z``) and their ``params (S, 4, m)``; ``dim_z``, ``dim_c``;
    ``R (S, k, k)``; each row's group (``group (S, k)``) and ``n_groups``; the χ² threshold of each
    group (``gates (S, g)``, ``≤ 0``: not gated); ``reset_after_s`` (``≤ 0``: never); ``corrected (S, p)``,
    the gain's rows kept; for a reset that needs the refused readings to agree, ``whiten (S, k, k)`` and
    the normal quantile ``agree_z (S,)`` of :func:`~quadlib.model_filter.agreement_test` (NaN: not needed)."""

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
    whiten: np.ndarray
    agree_z: np.ndarray


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


class SigmaArrays(NamedTuple):
    """A UKF's sigma points: the weights ``Wm``, ``Wc``, ``scale = λ + n`` of
    ``U = chol(scale · P)``, and an additive state's ``⊟`` and mean (``kinds (2,)``, ``-1``: ``x₁ − x₀``
    and ``w X``) with their ``params (2, m)``."""

    Wm: np.ndarray
    Wc: np.ndarray
    scale: float
    kinds: np.ndarray
    params: np.ndarray


@njit(cache=True, inline="always")
def normalized(m, x, P):
    """``normalize`` after a step (an additive model's ``P`` carried through its Jacobian)."""
    k, p = m.kinds, m.params
    if k[NORM] < 0:
        return x, P
    if not m.error_state and k[NORM_JAC] >= 0:
        J = normalize_jacobian(k[NORM_JAC], x, p[NORM_JAC])
        P = product(product(J, P), J.T)
    return normalize(k[NORM], x, p[NORM]), P


@njit(cache=True, inline="always")
def settle(m, x, e, P):
    """The state after a correction ``e``: folded in (``x ⊞ e``, when ``e`` is not zero) or added, then
    :func:`normalized`."""
    if not m.error_state:
        return normalized(m, x + e, P)
    for i in range(e.shape[0]):
        if e[i] != 0.0:
            return normalized(m, state_add(m.kinds[ADD], x, e, m.params[ADD]), P)
    return normalized(m, x, P)


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
def step_noise(m, u, dt, q_dt, Q):
    """The step's process noise ``Q(Δt)`` plus the input's, and the ``(q_dt, Q)`` to reuse."""
    k, p = m.kinds, m.params
    if abs(dt - q_dt) > 1e-9 * dt:
        q_dt, Q = dt, process_noise(k[Q_], dt, p[Q_])
    Q_k = Q
    if k[INPUT] >= 0:
        added, extra = input_noise(k[INPUT], u, dt, p[INPUT])
        if added:
            Q_k = Q + extra
    return Q_k, q_dt, Q


@njit(cache=True, inline="always")
def ekf_predict(m, x, P, u, dt, q_dt, Q):
    """ModelEKF's predict: ``(x, P, q_dt, Q, healthy)`` (always healthy)."""
    k, p = m.kinds, m.params
    Q_k, q_dt, Q = step_noise(m, u, dt, q_dt, Q)
    if k[JAC] == IDENTITY:  # I P Iᵀ is P exactly
        P = P + Q_k
    else:
        P = _propagated(jacobian(k[JAC], x, u, dt, p[JAC]), P, Q_k)
    x, P = normalized(m, transition(k[G_], x, u, dt, p[G_]), P)
    return x, P, q_dt, Q, True


@njit(cache=True, inline="always")
def _linearized(m, sens, s, x, c):
    """``H`` over ``P``'s coordinates, and ``ẑ``."""
    H = measurement_jacobian(sens.kinds[s, 1], x, c, sens.params[s, 1])
    z_hat = measure(sens.kinds[s, 0], x, c, sens.params[s, 0])
    if m.error_state and m.kinds[ADD_JAC] >= 0:
        return product(H, add_jacobian(m.kinds[ADD_JAC], x, m.params[ADD_JAC])), z_hat
    return H, z_hat


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
    SI = np.full((1, 1), 1.0 / S[0, 0]) if k == 1 else inverse(S)
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
    # Joseph's form (I − K H) P (I − K H)ᵀ + K R Kᵀ without forming I − K H, in O(n² k):
    # B = P − K (H P) (H P = PHTᵀ, P symmetric), then B − (B Hᵀ) Kᵀ + (K R) Kᵀ, the upper triangle
    B = P.copy()
    for i in range(n):
        if corrected[i]:
            for j in range(n):
                acc = 0.0
                for a in range(k):
                    acc += K[i, a] * PHT[j, a]
                B[i, j] -= acc
    BHT, KR = np.zeros((n, k)), np.zeros((n, k))
    for i in range(n):
        for a in range(k):
            for m_ in range(n):
                BHT[i, a] += B[i, m_] * H[a, m_]
            for b in range(k):
                KR[i, a] += K[i, b] * R[b, a]
    P_new = np.empty((n, n))
    for i in range(n):
        for j in range(i, n):
            acc = B[i, j]
            for a in range(k):
                acc += (KR[i, a] - BHT[i, a]) * K[j, a]
            P_new[i, j] = acc
            P_new[j, i] = acc
    x_new, P_new = settle(m, x, e, P_new)
    return x_new, P_new, S, SI


@njit(cache=True, inline="always")
def residual_rows(kind, z, z_hat, p, rows, every):
    """The innovation of the rows ``rows`` (all of them when ``every``): a residual kernel sees the
    full vectors with the other rows zero (:meth:`~quadlib.model.Sensor.subset`)."""
    if every:
        return residual(kind, z, z_hat, p)
    if kind < 0:
        return z[rows] - z_hat[rows]
    z_in, z_hat_in = np.zeros(z.shape[0]), np.zeros(z.shape[0])
    z_in[rows], z_hat_in[rows] = z[rows], z_hat[rows]
    return residual(kind, z_in, z_hat_in, p)[rows]


@njit(cache=True, inline="always")
def ekf_correct(m, sens, s, x, P, z, c, rows):
    """ModelEKF's update with the rows ``rows`` of sensor ``s``'s sample ``z``: the settled state,
    Joseph's ``P``, the innovation, ``S``, ``S⁻¹`` and whether it was healthy (always)."""
    kz = sens.dim_z[s]
    every = rows.shape[0] == kz
    H, z_hat = _linearized(m, sens, s, x, c)
    y = residual_rows(sens.kinds[s, 2], z, z_hat, sens.params[s, 2], rows, every)
    if every:
        x1, P1, S, SI = _correct(m, x, P, H, y, sens.R[s, :kz, :kz], sens.corrected[s])
    else:
        x1, P1, S, SI = _correct(m, x, P, np.ascontiguousarray(H[rows]), y,
                                 np.ascontiguousarray(sens.R[s][rows][:, rows]), sens.corrected[s])
    return x1, P1, y, S, SI, True


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
            x_s = state_add(k[ADD], x, times(C, residual_x(k[DIFF], xs_s[i + 1], x_prior, p[DIFF])), p[ADD])
        else:
            x_s = x + times(C, xs_s[i + 1] - x_prior)
        if k[NORM] >= 0:
            x_s = normalize(k[NORM], x_s, p[NORM])
        xs_s[i] = x_s
        P_s = P + product(product(C, Ps_s[i + 1] - prior_P), C.T)
        Ps_s[i] = 0.5 * (P_s + P_s.T)
    return xs_s, Ps_s
