"""The inertial navigation model and its GPS and barometer as numba kernels (:mod:`quadlib.kernels`).

State ``x = [q_nb (4), v (3), p (3), b_g (3), b_a (3)]``, input ``u = [ω_m, f_m]``, error
``δx = [δθ, δv, δp, δb_g, δb_a]``; the readable description, with its equations, is
:mod:`quadlib.nav.ins`, whose factories bind these. The error's ``⊞``, ``⊟``, ``∂⊞/∂δ`` and the
quaternion's normalisation are the attitude model's (:mod:`quadlib.kernels.attitude`: a quaternion
first, the rest added), and so are the attitude rows of the error Jacobian; the magnetometer's
heading is :func:`~quadlib.attitude.heading_sensor`'s.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels.attitude import attitude_bias_jacobian, turn_into
from quadlib.kernels.quaternion import dcm_entries

__all__: list[str] = []  # bound by the factories of quadlib.nav.ins


@njit(cache=True)
def strapdown_step(x, u, dt, p):
    """``g``: ``q ⊗ exp((ω_m − b_g) Δt)``, ``a = R(q) (f_m − b_a) + g_n``, ``v + a Δt``,
    ``p + v Δt + ½ a Δt²``; ``p = g_n`` (3)."""
    R = dcm_entries(x)  # R[i, j] is R[3 i + j]
    out = x.copy()
    turn_into(out, x, (u[0] - x[10]) * dt, (u[1] - x[11]) * dt, (u[2] - x[12]) * dt)
    f0, f1, f2 = u[3] - x[13], u[4] - x[14], u[5] - x[15]
    for i in range(3):
        a = R[3 * i] * f0 + R[3 * i + 1] * f1 + R[3 * i + 2] * f2 + p[i]
        out[4 + i] = x[4 + i] + a * dt
        out[7 + i] = x[7 + i] + x[4 + i] * dt + 0.5 * a * dt * dt
    return out


@njit(cache=True)
def strapdown_error_jacobian(x, u, dt, p):
    """``G`` over the 15 errors: the attitude-and-bias rows of the gyro step, ``∂δv⁺/∂δθ = −Δt R [f]×``,
    ``∂δv⁺/∂δb_a = −Δt R``, the position's half of each times ``Δt``, ``∂δp⁺/∂δv = Δt I``."""
    phi = np.empty(3)
    for i in range(3):
        phi[i] = (u[i] - x[10 + i]) * dt
    A = attitude_bias_jacobian(phi, dt)
    R = dcm_entries(x)  # R[i, j] is R[3 i + j]
    f0, f1, f2 = u[3] - x[13], u[4] - x[14], u[5] - x[15]
    F = np.eye(15)
    for i in range(3):
        r0, r1, r2 = R[3 * i], R[3 * i + 1], R[3 * i + 2]
        rf = (r1 * f2 - r2 * f1, r2 * f0 - r0 * f2, r0 * f1 - r1 * f0)  # row i of R [f]×
        for j in range(3):
            F[i, j], F[i, 9 + j] = A[i, j], A[i, 3 + j]
            F[3 + i, j], F[3 + i, 12 + j] = -dt * rf[j], -dt * R[3 * i + j]
            F[6 + i, j], F[6 + i, 12 + j] = 0.5 * dt * F[3 + i, j], 0.5 * dt * F[3 + i, 12 + j]
        F[6 + i, 3 + i] = dt
    return F


@njit(cache=True)
def strapdown_noise(dt, p):
    """``Q(Δt)``, ``p = [σ_g, σ_a,x, σ_a,y, σ_a,z, σ_bg, σ_ba]``: ``(σ_g Δt)²`` per attitude axis; one
    acceleration error shared by velocity (``σ_a² Δt²``) and position (``σ_a² Δt⁴/4``, their covariance
    ``σ_a² Δt³/2``); the bias walks ``σ² Δt``."""
    Q = np.zeros((15, 15))
    for i in range(3):
        sa2 = p[1 + i] ** 2
        Q[i, i] = (p[0] * dt) ** 2
        Q[3 + i, 3 + i] = sa2 * dt**2
        Q[6 + i, 6 + i] = sa2 * dt**4 / 4.0
        Q[3 + i, 6 + i] = Q[6 + i, 3 + i] = sa2 * dt**3 / 2.0
        Q[9 + i, 9 + i] = p[4] ** 2 * dt
        Q[12 + i, 12 + i] = p[5] ** 2 * dt
    return Q
