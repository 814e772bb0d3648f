"""Kesten's five attitude filters' own pieces as numba kernels (:mod:`quadlib.kernels`).

The readable description, with the thesis's equations and where the code differs from it, is
:mod:`quadlib.attitude.kesten`, whose factories bind these (with the shared pieces of
:mod:`quadlib.kernels.attitude`) into each filter's model and sensors.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.kernels.attitude import turn_into
from quadlib.kernels.quaternion import exp_rotvec, multiply, rotvec

__all__: list[str] = []  # bound by the factories of quadlib.attitude.kesten


@njit(cache=True)
def quaternion_step(x, u, dt, p):
    """``g``: ``q ⊗ exp(ω Δt)`` (eq. 2.7)."""
    out = np.empty(4)
    turn_into(out, x, u[0] * dt, u[1] * dt, u[2] * dt)
    return out


@njit(cache=True)
def orientation_vector_step(x, u, dt, p):
    """``g`` of TOVKF's orientation vector θ: the rotation vector of ``exp(θ) ⊗ exp(ω Δt)``."""
    q = np.empty(4)
    turn_into(q, exp_rotvec(x), u[0] * dt, u[1] * dt, u[2] * dt)
    return rotvec(q)


@njit(cache=True)
def rotation_blocks_add(x, d, p):
    """``q ⊞ δ = q ⊗ exp(δ₁) ⊗ exp(δ₂) …`` over ``p[0]`` blocks of 3, each non-zero block in turn."""
    q = x.copy()
    for b in range(int(p[0])):
        if d[3 * b] != 0.0 or d[3 * b + 1] != 0.0 or d[3 * b + 2] != 0.0:
            turn_into(q, q.copy(), d[3 * b], d[3 * b + 1], d[3 * b + 2])
    return q


@njit(cache=True)
def rotation_blocks_difference(x1, x0, p):
    """One right inverse of :func:`rotation_blocks_add`: the whole turn ``rotvec(q₀* ⊗ q₁)`` in the first block."""
    out = np.zeros(3 * int(p[0]))
    out[:3] = rotvec(multiply(np.array([x0[0], -x0[1], -x0[2], -x0[3]]), x1))
    return out


@njit(cache=True)
def quaternion_rotvec(x, c, p):
    """``h``: the rotation vector of the state's quaternion (TQF's measured attitude)."""
    return rotvec(x)


@njit(cache=True)
def nearest_orientation(z, z_hat, p):
    """TOVKF's residual: ``z`` or the same attitude turned the other way round, whichever is nearer ``ẑ``."""
    angle = math.sqrt(z[0] * z[0] + z[1] * z[1] + z[2] * z[2])
    if angle < 1e-12:
        return z - z_hat
    other = z - 2 * np.pi * z / angle
    near, far = 0.0, 0.0
    for i in range(3):
        near += (z[i] - z_hat[i]) ** 2
        far += (other[i] - z_hat[i]) ** 2
    return (z if math.sqrt(near) <= math.sqrt(far) else other) - z_hat


@njit(cache=True)
def same_sign_quaternion(z, z_hat, p):
    """TQKF's residual: the measured quaternion's sign matched to the predicted one's, then subtracted."""
    dot = 0.0
    for i in range(z.shape[0]):
        dot += z[i] * z_hat[i]
    return (z if dot >= 0 else -z) - z_hat


@njit(cache=True)
def rotvec_turn(z, z_hat, p):
    """TQF's residual: the turn from the attitude ``exp(ẑ)`` to ``exp(z)`` as a rotation vector."""
    q_hat = exp_rotvec(z_hat)
    return rotvec(multiply(np.array([q_hat[0], -q_hat[1], -q_hat[2], -q_hat[3]]), exp_rotvec(z)))


@njit(cache=True)
def turn_between(z, z_hat, p):
    """QF's residual: the rotation vector that turns the measured direction ``z`` onto the predicted
    ``ẑ`` (eqs. 2.61, 2.63): axis ``z × ẑ``, angle between them."""
    ax, ay, az, bx, by, bz = z[0], z[1], z[2], z_hat[0], z_hat[1], z_hat[2]
    na, nb = math.sqrt(ax * ax + ay * ay + az * az), math.sqrt(bx * bx + by * by + bz * bz)
    ax, ay, az, bx, by, bz = ax / na, ay / na, az / na, bx / nb, by / nb, bz / nb
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    s = math.sqrt(cx * cx + cy * cy + cz * cz)
    if s < 1e-12:
        return np.zeros(3)
    angle = math.acos(min(1.0, max(-1.0, ax * bx + ay * by + az * bz)))
    return np.array([cx / s, cy / s, cz / s]) * angle
