"""Chapter 11's 3D quadrotor model as numba kernels (:mod:`quadlib.kernels`).

State ``x = [p (3), v (3), ψ]`` (NED), input ``u = [f_b (3), ψ̇, φ, θ]``. The readable description,
with Tellex et al.'s equations and the corrected gravity sign, is
:func:`~quadlib.quad.quad3d.quad3d_model`, which binds these; its GPS and magnetometer bind the
linear measurement of :mod:`quadlib.kernels.attitude` (:func:`~quadlib.engine.kernel.linear_kernels`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels.linalg import wrap
from quadlib.kernels.quaternion import euler_dcm

__all__: list[str] = []  # bound by quadlib.quad.quad3d

YAW = 6


@njit(cache=True)
def quad3d_step(x, u, dt, p):
    """``g`` (eq. 49): ``[p + v Δt, v + (R_nb f + g_n) Δt, ψ + ψ̇ Δt]`` with ``g_n = [0, 0, p[0]]``, the
    yaw wrapped to (−π, π]."""
    R = euler_dcm(u[4], u[5], x[YAW])
    out = np.empty(7)
    for i in range(3):
        f_n = R[i, 0] * u[0] + R[i, 1] * u[1] + R[i, 2] * u[2] + (p[0] if i == 2 else 0.0)
        out[i] = x[i] + x[3 + i] * dt
        out[3 + i] = x[3 + i] + f_n * dt
    out[YAW] = wrap(x[YAW] + u[3] * dt)
    return out


@njit(cache=True)
def quad3d_jacobian(x, u, dt, p):
    """``G`` (eqs. 50–52): ``∂g/∂x``; the yaw column is ``∂R/∂ψ f Δt``, whose rows are ``(−R₁, R₀, 0)``."""
    J = np.eye(7)
    R = euler_dcm(u[4], u[5], x[YAW])
    for i in range(3):
        J[i, 3 + i] = dt
    f0, f1, f2 = u[0] * dt, u[1] * dt, u[2] * dt
    J[3, YAW] = (-R[1, 0]) * f0 + (-R[1, 1]) * f1 + (-R[1, 2]) * f2
    J[4, YAW] = R[0, 0] * f0 + R[0, 1] * f1 + R[0, 2] * f2
    return J


@njit(cache=True)
def quad3d_noise(dt, p):
    """``Q(Δt)``, ``p = [σ_x, σ_y, σ_z, σ_ψ̇]``: white acceleration per axis (``σ Δt²/2`` on the
    position, ``σ Δt`` on the velocity, fully correlated) and the yaw rate's ``(σ_ψ̇ Δt)²``."""
    Q = np.zeros((7, 7))
    for i in range(3):
        w0, w1 = 0.5 * dt**2 * p[i], dt * p[i]
        Q[i, i], Q[i, i + 3], Q[i + 3, i], Q[i + 3, i + 3] = w0 * w0, w0 * w1, w1 * w0, w1 * w1
    Q[YAW, YAW] = (p[3] * dt) ** 2
    return Q
