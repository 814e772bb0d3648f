"""The small linear algebra the compiled engine (:mod:`quadlib.engine`) and the models' kernels share:
products and inverses of small matrices, the Cholesky factor of the sigma points, the repair of an
indefinite covariance, and the wrapping of an angle. Plain loops on small arrays, compiled by numba:
for a few rows, a BLAS or LAPACK call costs more than the sums."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__: list[str] = []  # internal: the compiled code uses these


@njit(cache=True)
def wrap(a):
    """:func:`~quadlib.geometry.rotations.wrap_angle` of one angle [rad]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


@njit(cache=True)
def product(A, B):
    """``A @ B`` for the filters' small matrices, as plain loops: for a few rows, BLAS's call costs
    more than the sums."""
    C = np.zeros((A.shape[0], B.shape[1]))
    for i in range(A.shape[0]):
        for k in range(A.shape[1]):
            a = A[i, k]
            for j in range(B.shape[1]):
                C[i, j] += a * B[k, j]
    return C


@njit(cache=True)
def times(A, v):
    """``A v`` as plain loops (``A.T`` passes without a copy)."""
    out = np.zeros(A.shape[0])
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            out[i] += A[i, j] * v[j]
    return out


@njit(cache=True)
def add_outer(A, w, a, b):
    """``A += w aᵀb`` in place, each term ``w (aᵢ bⱼ)`` as ``w * np.outer(a, b)`` gives it, without the
    two temporary arrays (a UKF sums one per sigma point)."""
    for i in range(a.shape[0]):
        for j in range(b.shape[0]):
            A[i, j] += w * (a[i] * b[j])


@njit(cache=True)
def inverse(S):
    """``S⁻¹`` of a small invertible matrix (Gauss–Jordan elimination with partial pivoting)."""
    n = S.shape[0]
    A, X = S.copy(), np.eye(n)
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(A[r, c]) > abs(A[p, c]):
                p = r
        for j in range(n):
            A[c, j], A[p, j] = A[p, j], A[c, j]
            X[c, j], X[p, j] = X[p, j], X[c, j]
        d = A[c, c]
        for j in range(n):
            A[c, j] /= d
            X[c, j] /= d
        for r in range(n):
            f = A[r, c]
            if r != c and f != 0.0:
                for j in range(n):
                    A[r, j] -= f * A[c, j]
                    X[r, j] -= f * X[c, j]
    return X


@njit(cache=True)
def upper_cholesky(A):
    """``U`` with ``Uᵀ U = A``, and whether ``A`` was positive definite."""
    n = A.shape[0]
    U = np.zeros((n, n))
    for j in range(n):
        d = A[j, j]
        for m in range(j):
            d -= U[m, j] * U[m, j]
        if not d > 0.0:
            return U, False
        U[j, j] = math.sqrt(d)
        for i in range(j + 1, n):
            v = A[j, i]
            for m in range(j):
                v -= U[m, j] * U[m, i]
            U[j, i] = v / U[j, j]
    return U, True


@njit(cache=True)
def positive_definite(P):
    """:func:`quadlib.filters.positive_definite`: symmetrised, and if indefinite its eigenvalues
    raised to 1e-12 of the largest."""
    P = 0.5 * (P + P.T)
    if upper_cholesky(P)[1]:
        return P
    w, V = np.linalg.eigh(P)
    return (V * np.maximum(w, 1e-12 * max(w.max(), 2.2250738585072014e-308))) @ V.T  # np.finfo(float).tiny


@njit(cache=True)
def add_refused(acc, w, group, rejected):
    """Add a whitened reading ``w`` (one value per row, ``group[r]`` the row's group) to the lock-out of
    each group the gate ``rejected``. ``acc (g, k + 2)`` holds, per group, ``Σ w`` over its rows, then the
    count of readings, then ``Σ |w|²``: what :func:`scatter_agrees` tests."""
    k = acc.shape[1] - 2
    for g in range(rejected.shape[0]):
        if rejected[g]:
            acc[g, k] += 1.0
            for r in range(w.shape[0]):
                if group[r] == g:
                    acc[g, r] += w[r]
                    acc[g, k + 1] += w[r] * w[r]


@njit(cache=True)
def scatter_agrees(acc, dof_per_reading, z):
    """Whether the whitened readings of one lock-out (noise ``R`` made unit; ``acc`` is their
    :func:`add_refused` row: ``Σ w``, the count ``n``, ``Σ |w|²``) scatter about their own mean no more
    than noise ``R`` would: the scatter ``Σ|wᵢ − w̄|² = Σ |w|² − |Σ w|²/n`` within the χ² quantile of
    ``(n − 1) · dof_per_reading`` degrees of freedom at the normal quantile ``z`` (Wilson & Hilferty's
    approximation, ``ν (1 − a + z √a)³`` with ``a = 2 / 9ν``; at 0.999 within 2 % of the quantile from
    ν = 3, 0.6 % from ν = 10)."""
    k = acc.shape[0] - 2
    count, scatter = acc[k], acc[k + 1]
    if count < 2:
        return False
    for i in range(k):
        scatter -= acc[i] * acc[i] / count
    dof = (count - 1) * dof_per_reading
    a = 2.0 / (9.0 * dof)
    return scatter <= dof * (1.0 - a + z * math.sqrt(a)) ** 3
