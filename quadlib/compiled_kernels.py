"""The numba kernels the compiled filters share besides the one-quaternion maths
(:mod:`quadlib.geometry.kernels`): small matrix products and inverses, the Kalman update, the
Cholesky factor of the sigma points, the attitude-and-bias error Jacobian.

Every function here is plain arithmetic on small arrays, compiled by numba; the compiled filters
(:mod:`quadlib.engine`, the models' kernels of :mod:`quadlib.kernels`) are proved equal to their
readable twins by their tests, and with them these kernels.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from numba import njit

from quadlib.constants import SATURATED
from quadlib.geometry.kernels import dcm, exp_rotvec, skew

__all__: list[str] = []  # internal: the compiled filters use these


def called_from_python(loop):
    """``loop``, a compiled function that Python calls, with each array argument made C-contiguous
    and writable first. numba compiles one machine code per layout and read-only flag of its
    arguments: a column view or a read-only log would each cost another compile (15-20 s), on every
    fresh install, in whichever test or chapter met it first. ``py_func`` is the uncompiled loop."""

    @functools.wraps(loop)
    def call(*args):
        return loop(*(np.require(a, requirements="CW") if isinstance(a, np.ndarray) else a for a in args))

    call.py_func = loop.py_func
    return call










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
def kalman_update(P, H, y, R, corrected, gate):
    """One EKF update of the error state (zero before it): the error ``K y``, Joseph's covariance,
    the NIS, ``S``, and whether the gate (``gate ≤ 0``: none) passed it. Gain rows where the bool
    mask ``corrected`` is False are zero (a consider update, :attr:`quadlib.model.Sensor.uncorrected`)."""
    n, m = P.shape[0], y.shape[0]
    PHT = product(P, H.T)
    S = product(H, PHT) + R
    SI = inverse(S)
    nis = 0.0
    for i in range(m):
        for j in range(m):
            nis += y[i] * SI[i, j] * y[j]
    if gate > 0.0 and nis > gate:
        return np.zeros(n), P, nis, S, False
    K = product(PHT, SI)
    for i in range(n):
        if not corrected[i]:
            K[i, :] = 0.0
    I_KH = np.eye(n) - product(K, H)
    P_new = product(product(I_KH, P), I_KH.T) + product(product(K, R), K.T)
    e = np.zeros(n)
    for i in range(n):
        for j in range(m):
            e[i] += K[i, j] * y[j]
    return e, P_new, nis, S, True



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
def attitude_bias_jacobian(phi, dt):
    """``∂δx⁺/∂δx`` over ``[δθ, δb]`` of one gyro step ``φ = (ω − b) Δt``
    (:func:`~quadlib.attitude.bias_model.gyro_error_jacobians`)."""
    theta = math.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    K = skew(phi)
    if theta > 1e-6:
        a, b = (1.0 - math.cos(theta)) / theta**2, (theta - math.sin(theta)) / theta**3
    else:
        a, b = 0.5 - theta**2 / 24.0, 1.0 / 6.0 - theta**2 / 120.0
    G = np.eye(6)
    G[:3, :3] = dcm(exp_rotvec(phi)).T
    G[:3, 3:] = -dt * (np.eye(3) - a * K + b * product(K, K))
    return G



@njit(cache=True)
def saturated(u, gyro_range):
    """The gyro sample ``u`` is at its full scale (:func:`~quadlib.imu.saturated_step_variance`);
    ``gyro_range ≤ 0``: a gyro that never saturates."""
    return gyro_range > 0.0 and np.abs(u).max() >= SATURATED * gyro_range


@njit(cache=True)
def diverged(x, P):
    """The estimate is no longer finite: a compiled loop stops and hands the log to ``run_filter``."""
    return not (np.isfinite(x).all() and np.isfinite(P).all())
