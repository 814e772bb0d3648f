"""Salmony's fixed-wing attitude model (2019): quaternion + gyro bias, accelerometer with airspeed.

State ``x = [q0, q1, q2, q3, b_p, b_q, b_r]`` (eq. 3): ``q_nb`` scalar first and the gyro biases
[rad/s]; input the gyro rates ``ω = [p, q, r]``. Continuous dynamics (eqs. 9–11, corrected):

.. math::

    \\dot q = \\tfrac12\\,\\Xi(q)\\,(\\omega - b), \\qquad \\dot b = 0, \\qquad
    \\Xi(q) = \\begin{bmatrix} -q_1 & -q_2 & -q_3 \\\\ q_0 & -q_3 & q_2 \\\\ q_3 & q_0 & -q_1 \\\\
        -q_2 & q_1 & q_0 \\end{bmatrix}

Measurements: the accelerometer with the airspeed terms of eq. (13) (level flight along body x at
airspeed ``V_a``, ``a^b = ω × [V_a, 0, 0] − R(q)ᵀ g_n``) and the magnetometer as a unit vector
(eq. 14, with an optional inclination the document leaves out). All functions are pure; the
Jacobians are exact and tested against sympy and finite differences.

Differs from the source (errata E18–E21, chapter 12 and the appendix): eq. (11) already holds
the ½ that eq. (10) applies again; eq. (12)'s last row has the wrong sign on ``∂q̇₃/∂b_r``;
eq. (14)'s second row has the wrong sign on its ``q₁q₂`` term (the printed C matrix is the
Jacobian of the corrected row).
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import G0, earth_field_ned
from quadlib.geometry.quaternion import quat_to_dcm

__all__ = ["accel_jacobian", "accel_model", "airspeed_from_pressure", "fixedwing_A", "fixedwing_f",
           "lowpass2", "mag_jacobian", "mag_model", "quaternion_rate_matrix"]



def quaternion_rate_matrix(q) -> np.ndarray:
    """``Ξ(q)``, ``(4, 3)``: ``q̇ = ½ Ξ(q) ω`` for body rates ω (eq. 11 without its ½)."""
    q0, q1, q2, q3 = q
    return np.array([[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]])


def fixedwing_f(x, omega) -> np.ndarray:
    """``ẋ = f(x, ω)`` (eqs. 9–11, corrected): ``(7,)``."""
    x = np.asarray(x, dtype=float)
    return np.concatenate([0.5 * quaternion_rate_matrix(x[:4]) @ (np.asarray(omega, dtype=float) - x[4:]),
                           np.zeros(3)])


def fixedwing_A(x, omega) -> np.ndarray:
    """``A = ∂f/∂x`` (eq. 12, corrected), ``(7, 7)``."""
    x = np.asarray(x, dtype=float)
    p, q, r = np.asarray(omega, dtype=float) - x[4:]
    A = np.zeros((7, 7))
    A[:4, :4] = 0.5 * np.array([[0, -p, -q, -r], [p, 0, r, -q], [q, -r, 0, p], [r, q, -p, 0]])
    A[:4, 4:] = -0.5 * quaternion_rate_matrix(x[:4])
    return A


def accel_model(x, omega, airspeed_m_s: float, g: float = G0) -> np.ndarray:
    """Eq. (13): specific force in the body frame, ``(3,)`` [m/s²]."""
    x = np.asarray(x, dtype=float)
    p, q, r = np.asarray(omega, dtype=float) - x[4:]
    return np.array([0.0, airspeed_m_s * r, -airspeed_m_s * q]) - g * quat_to_dcm(x[:4])[2]


def accel_jacobian(x, omega, airspeed_m_s: float, g: float = G0) -> np.ndarray:
    """``∂(eq. 13)/∂x``, ``(3, 7)`` (the first three rows of Salmony's C)."""
    q0, q1, q2, q3 = np.asarray(x, dtype=float)[:4]
    C = np.zeros((3, 7))
    C[:, :4] = -2.0 * g * np.array([[-q2, q3, -q0, q1], [q1, q0, q3, q2], [0.0, -2 * q1, -2 * q2, 0.0]])
    C[1, 6], C[2, 5] = -airspeed_m_s, airspeed_m_s
    return C


def mag_model(x, declination_rad: float, inclination_rad: float = 0.0) -> np.ndarray:
    """Eq. (14), corrected: the unit field ``R(q)ᵀ m_n`` in the body frame. The document's
    model is ``inclination_rad = 0`` (a horizontal field)."""
    return quat_to_dcm(np.asarray(x, dtype=float)[:4]).T @ earth_field_ned(1.0, inclination_rad, declination_rad)


def mag_jacobian(x, declination_rad: float, inclination_rad: float = 0.0) -> np.ndarray:
    """``∂(mag_model)/∂x``, ``(3, 7)``, exact: the model is a quadratic polynomial in ``q``, so a
    central difference with unit steps has no truncation error."""
    q = np.asarray(x, dtype=float)[:4]
    steps = np.vstack([q + np.eye(4), q - np.eye(4)])  # the eight points, one rotation-matrix call
    fields = np.einsum("nji,j->ni", quat_to_dcm(steps), earth_field_ned(1.0, inclination_rad, declination_rad))
    C = np.zeros((3, 7))
    C[:, :4] = ((fields[:4] - fields[4:]) / 2.0).T
    return C


def lowpass2(x, cutoff_hz: float, dt: float) -> np.ndarray:
    """Eq. (8): the critically damped second-order low-pass (eq. 7) by backward Euler, ``(N, ...)``.

    Starts from rest at the first sample (``y₋₁ = y₋₂ = x₀``), so a constant input passes unchanged.
    """
    x = np.asarray(x, dtype=float)
    wt = 2 * np.pi * float(cutoff_hz) * float(dt)
    den = 1 + 2 * wt + wt**2
    y = np.empty_like(x)
    y1 = y2 = x[0]
    for n in range(len(x)):
        y[n] = (wt**2 * x[n] + 2 * (1 + wt) * y1 - y2) / den
        y2, y1 = y1, y[n]
    return y


def airspeed_from_pressure(dp_pa, rho_kg_m3: float = 1.225) -> np.ndarray:
    """Eq. (2): pitot airspeed ``√(2 ΔP / ρ)`` [m/s]."""
    dp = np.asarray(dp_pa, dtype=float)
    if np.any(dp < 0):
        raise ValueError(f"dp_pa: expected non-negative differential pressures, got a minimum of {dp.min()}")
    return np.sqrt(2.0 * dp / float(rho_kg_m3))
