"""Linear quadratic regulators: python-control's ``lqr``, checked against scipy's Riccati solver, and
Kesten's altitude PID whose gains come from one (Kesten §3.1, eqs. 3.2–3.7; §4.6.1).

For ``ẋ = A x + B u`` and the cost ``∫ xᵀQx + uᵀRu dt`` the optimal law is ``u = −K x`` with
``K = R⁻¹ Bᵀ P`` and ``P`` the stabilising solution of the continuous algebraic Riccati equation
``Aᵀ P + P A − P B R⁻¹ Bᵀ P + Q = 0``.

Kesten's altitude model (eq. 3.3) is a double integrator with an integral state,
``x = [e, s, v]`` with ``ė = s`` (the altitude error's integral, the reference at 0), ``ṡ = v``,
``v̇ = u/m``, and ``u = T − T₀`` the thrust beyond hover. Its law ``u = −K x`` is eq. (3.2) with
``(c_i, c_p, c_d) = −K`` (the sign is erratum E35: eq. 3.7 prints ``F = (c_i, c_p, c_d)`` without it).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.linalg

from quadlib.validation import as_covariance, as_finite_array, as_positive

__all__ = ["AltitudeGains", "altitude_model_matrices", "altitude_pid_gains", "lqr_gain", "riccati_gain"]


def _system(A, B, Q, R):
    A = as_finite_array("A", A, ndim=2)
    n = A.shape[0]
    if A.shape != (n, n):
        raise ValueError(f"A: expected a square matrix, got shape {A.shape}")
    B = as_finite_array("B", B, ndim=2)
    if B.shape[0] != n:
        raise ValueError(f"B: expected {n} rows to match A, got shape {B.shape}")
    Q = as_covariance("Q", Q, n)
    R = as_covariance("R", R, B.shape[1], definite=True)
    return A, B, Q, R


def lqr_gain(A, B, Q, R) -> np.ndarray:
    """``K`` (m, n) of the optimal law ``u = −K x``, from python-control's ``lqr``."""
    import control  # only the controller design needs it

    A, B, Q, R = _system(A, B, Q, R)
    K, _, _ = control.lqr(A, B, Q, R)
    return np.asarray(K, dtype=float)


def riccati_gain(A, B, Q, R) -> np.ndarray:
    """The same ``K`` from scipy's solution of the Riccati equation: ``K = R⁻¹ Bᵀ P``."""
    A, B, Q, R = _system(A, B, Q, R)
    P = scipy.linalg.solve_continuous_are(A, B, Q, R)
    return np.linalg.solve(R, B.T @ P)


class AltitudeGains(NamedTuple):
    """Kesten's altitude PID gains (eq. 3.2): integral, proportional, derivative [N/(m s), N/m, N/(m/s)]."""

    c_i: float
    c_p: float
    c_d: float


def altitude_model_matrices(mass_kg: float) -> tuple[np.ndarray, np.ndarray]:
    """``A``, ``B`` of eq. (3.3) for ``x = [e, s, v]`` and ``u = T − T₀``."""
    m = as_positive("mass_kg", mass_kg)
    return np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]]), np.array([[0.0], [0.0], [1.0 / m]])


def altitude_pid_gains(mass_kg: float = 1.1, q_e: float = 4.0, q_s: float = 2.0, q_v: float = 1.0,
                       r: float = 1.0) -> AltitudeGains:
    """Eqs. (3.3)–(3.7): the LQR gains of the altitude PID for ``Q = diag(q_e, q_s, q_v)``, ``R = r``.
    Defaults: Kesten's mass (eq. 4.1) and weights (eqs. 4.18–4.20)."""
    for name, value in (("q_e", q_e), ("q_s", q_s), ("q_v", q_v), ("r", r)):
        as_positive(name, value)
    A, B = altitude_model_matrices(mass_kg)
    K = lqr_gain(A, B, np.diag([q_e, q_s, q_v]), [[r]])[0]
    return AltitudeGains(c_i=float(-K[0]), c_p=float(-K[1]), c_d=float(-K[2]))
