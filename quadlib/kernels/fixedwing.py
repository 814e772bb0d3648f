"""Salmony's fixed-wing sensors as numba kernels (:mod:`quadlib.kernels`).

The readable descriptions, with the document's equations and their corrections, are
:func:`~quadlib.fixedwing.model.accel_model`, :func:`~quadlib.fixedwing.model.mag_model` and their
Jacobians, which call these, and the sensors of :mod:`quadlib.fixedwing.model`, which bind them.
The state is ``[q_nb, b]``; ``R(q)`` is written as ``1 − 2(y² + z²), …`` on the diagonal
(``quat_to_dcm``'s form), which for a unit ``q`` equals the homogeneous one; the Jacobians are those
of this form, off the unit sphere too.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels.quaternion import body_vector_jacobian, dcm_entries

__all__: list[str] = []  # bound by quadlib.fixedwing.model


@njit(cache=True)
def airspeed_accel(x, c, p):
    """Eq. (13): the specific force ``(3,)`` [m/s²] with context ``c = [p, q, r, V_a]`` (or ``[p, q, r]``),
    ``p = [g, with_airspeed]`` (0: the airspeed terms left out, a failed pitot)."""
    g, airspeed = p[0], c[3] if p[1] != 0.0 else 0.0
    w, qx, qy, qz = x[0], x[1], x[2], x[3]
    q, r = c[1] - x[5], c[2] - x[6]
    down0, down1, down2 = 2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)  # R(q)ᵀ e_z
    return np.array([-g * down0, airspeed * r - g * down1, -airspeed * q - g * down2])


@njit(cache=True)
def airspeed_accel_H(x, c, p):
    """``∂(eq. 13)/∂x``, ``(3, 7)`` (the first three rows of Salmony's C)."""
    g, airspeed = p[0], c[3] if p[1] != 0.0 else 0.0
    q0, q1, q2, q3 = x[0], x[1], x[2], x[3]
    C = np.zeros((3, 7))
    C[0, 0], C[0, 1], C[0, 2], C[0, 3] = 2 * g * q2, -2 * g * q3, 2 * g * q0, -2 * g * q1
    C[1, 0], C[1, 1], C[1, 2], C[1, 3] = -2 * g * q1, -2 * g * q0, -2 * g * q3, -2 * g * q2
    C[2, 1], C[2, 2] = 4 * g * q1, 4 * g * q2
    C[1, 6], C[2, 5] = -airspeed, airspeed
    return C


@njit(cache=True)
def unit_field(x, c, p):
    """Eq. (14), corrected: ``R(q)ᵀ m_n + (1 − |q|²) m_n`` with the unit field ``m_n = p[:3]``."""
    R = dcm_entries(x)  # R[i, j] is R[3 i + j]
    off = 1.0 - (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
    out = np.empty(3)
    for i in range(3):
        out[i] = R[i] * p[0] + R[3 + i] * p[1] + R[6 + i] * p[2] + off * p[i]
    return out


@njit(cache=True)
def unit_field_H(x, c, p):
    """``∂(eq. 14)/∂x``, ``(3, 7)``, exact: ``∂(R(q)ᵀ m_n)/∂q − 2 m_n qᵀ``."""
    C = np.zeros((3, 7))
    entries = body_vector_jacobian(x, p)
    for i in range(3):
        for j in range(4):
            C[i, j] = entries[4 * i + j] - 2.0 * p[i] * x[j]
    return C
