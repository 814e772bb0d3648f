"""The engine's arithmetic that no model's kernel enters: compiled once, shared by every filter's loop.

The per-filter code (:mod:`quadlib.engine.template`) calls a model's ``g``, ``G``, ``Q`` … and
hands the matrices they give to these: the covariance's propagation, the Kalman update with
Joseph's form and a consider mask, the χ² test of a sample's groups and the widening of a reset.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels.linalg import add_refused, inverse, product, scatter_agrees

__all__ = ["block", "gain_update", "groups_rejected", "lockout_cleared", "lockout_expired", "masked", "picked",
           "picked_rows", "propagated", "quadratic_form", "rows_where", "smoother_gain", "weighted_mean", "widened"]


@njit(cache=True)
def propagated(F, P, Q):
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


@njit(cache=True)
def gain_update(P, H, y, R, corrected):
    """The Kalman update of ``P`` with ``H``, the innovation ``y`` and ``R``: the correction ``e = K y``,
    Joseph's ``P``, ``S`` and ``S⁻¹``. The gain's rows of states not ``corrected`` are zero (a consider
    update), for which Joseph's form keeps ``P`` exact."""
    n, k = P.shape[0], y.shape[0]
    PHT = np.zeros((n, k))
    for i in range(n):
        for m in range(n):
            a = P[i, m]
            for j in range(k):
                PHT[i, j] += a * H[j, m]
    S = np.empty((k, k))
    for i in range(k):
        for j in range(k):
            acc = R[i, j]
            for m in range(n):
                acc += H[i, m] * PHT[m, j]
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
            for m in range(n):
                BHT[i, a] += B[i, m] * H[a, m]
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
    return e, P_new, S, SI


@njit(cache=True)
def quadratic_form(y, SI):
    """``yᵀ S⁻¹ y``: the NIS."""
    acc = 0.0
    for i in range(y.shape[0]):
        for j in range(y.shape[0]):
            acc += y[i] * SI[i, j] * y[j]
    return acc


@njit(cache=True)
def groups_rejected(nis, S, y, group, gates, force, rejected):
    """Which groups of a sample the χ² gate rejects, into ``rejected`` (``(g,)``, cleared first): one
    group against ``gates[0]`` on the whole NIS, several each on its own ``y_gᵀ S_g⁻¹ y_g``; groups in
    ``force`` pass; ``gates[0] ≤ 0``: none is gated."""
    rejected[:] = False
    if gates[0] <= 0.0:
        return
    ng = rejected.shape[0]
    if ng == 1:
        rejected[0] = nis > gates[0] and not force[0]
        return
    kz = y.shape[0]
    for g in range(ng):
        rows = np.array([r for r in range(kz) if group[r] == g])
        y_g = y[rows]
        rejected[g] = not force[g] and y_g @ np.linalg.solve(S[rows][:, rows], y_g) > gates[g]


@njit(cache=True)
def widened(P, J, y):
    """``P + J⁺ diag(y²) J⁺ᵀ``, symmetric: each direction a reset's rows measure (``J = ∂h/∂δ``) gets
    the variance of the discrepancy ``y`` it shows; directions below the noise stay out."""
    J_pinv = np.linalg.pinv(J, rcond=1e-6)
    P = P + product(product(J_pinv, np.diag(y**2)), J_pinv.T)
    return 0.5 * (P + P.T)


@njit(cache=True)
def weighted_mean(Z, w):
    """``w Z``: the plain weighted mean of the rows of ``Z``."""
    out = np.zeros(Z.shape[1])
    for r in range(Z.shape[0]):
        for j in range(Z.shape[1]):
            out[j] += w[r] * Z[r, j]
    return out


@njit(cache=True)
def lockout_expired(rejected, since, refused, t_j, reset_after_s, agree_z, whitened, group, expired):
    """The timed reset's bookkeeping after a sample the gate refused in part or whole: which of the
    ``rejected`` groups have been refused for ``reset_after_s`` [s] by ``t_j`` (into ``expired``) — and,
    when ``agree_z`` is not NaN, whose refused readings also agree with one another (their
    ``whitened`` innovations added to ``refused`` first, :func:`~quadlib.kernels.linalg.scatter_agrees`).
    ``since[g]`` (NaN: not locked out) is when group ``g``'s lock-out began."""
    agreeing = not np.isnan(agree_z)
    if agreeing:
        add_refused(refused, whitened, group, rejected)
    for g in range(rejected.shape[0]):
        expired[g] = False
        if rejected[g]:
            expired[g] = not np.isnan(since[g]) and t_j - since[g] >= reset_after_s
            if expired[g] and agreeing:
                expired[g] = scatter_agrees(refused[g], float(np.sum(group == g)), agree_z)
            if np.isnan(since[g]):
                since[g] = t_j


@njit(cache=True)
def lockout_cleared(rejected, since, refused):
    """End the lock-out of every group the last update did not reject (a gated sensor's)."""
    for g in range(rejected.shape[0]):
        if not rejected[g]:
            since[g] = np.nan
            refused[g] = 0.0


# Picking rows: written out here, compiled once, so that no filter's loop compiles numpy's fancy indexing

@njit(cache=True)
def rows_where(group, flags, value):
    """The rows ``r`` (ascending) whose group's flag ``flags[group[r]]`` is ``value``."""
    out, n = np.empty(group.shape[0], np.int64), 0
    for r in range(group.shape[0]):
        if flags[group[r]] == value:
            out[n] = r
            n += 1
    return out[:n]


@njit(cache=True)
def picked(v, rows):
    """``v[rows]``."""
    out = np.empty(rows.shape[0])
    for i in range(rows.shape[0]):
        out[i] = v[rows[i]]
    return out


@njit(cache=True)
def masked(v, rows):
    """``v`` with every row but ``rows`` zero."""
    out = np.zeros(v.shape[0])
    for r in rows:
        out[r] = v[r]
    return out


@njit(cache=True)
def picked_rows(A, rows):
    """``A[rows]``, C-contiguous."""
    out = np.empty((rows.shape[0], A.shape[1]))
    for i in range(rows.shape[0]):
        out[i] = A[rows[i]]
    return out


@njit(cache=True)
def block(A, rows):
    """``A[rows][:, rows]``, C-contiguous."""
    k = rows.shape[0]
    out = np.empty((k, k))
    for i in range(k):
        for j in range(k):
            out[i, j] = A[rows[i], rows[j]]
    return out


@njit(cache=True)
def smoother_gain(FP, prior_P):
    """The RTS gain ``C = P Fᵀ (P⁻)⁻¹`` from ``F P`` and the prior's ``P⁻`` (symmetric), C-contiguous."""
    return np.ascontiguousarray(np.linalg.solve(prior_P, FP).T)
