"""Kesten's controllers (§3): the altitude PID of eq. (3.2) and the quaternion attitude PID of
eqs. (3.8)–(3.11), with the three corrections the errata prove.

* E33: the tilt ``α`` that divides the thrust (eq. 3.8) is ``arccos C₃₃ = arccos(1 − 2(q₁² + q₂²))``,
  not the length of the orientation vector's x–y part (eq. 3.9).
* E34: the attitude error in the body frame, which eq. (3.11) feeds to the rotors, is
  ``θ(q̌⁻¹ ⊗ q̂)`` (eq. 3.10 writes the navigation-frame ``θ(q̂ ⊗ q̌⁻¹)``).
* E36: with the body frame of §1.2 (forward, right, down) the matrix of eq. (3.11) turns the body
  *positively* for a positive error (:data:`~quadlib.control.vehicle.MIXER`), so positive gains
  (eqs. 4.24–4.26) push the error up. Negative gains, as the altitude controller has (E35), close
  the loop: here ``T = T̄ + M u`` with ``u = C_p θ + C_i ∫θ + C_d (ω̂ − ω̌)`` and ``C`` negative.

Both controllers take the *estimated* state: the true one for perfect estimation, or a filter's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.control.lqr import AltitudeGains, lqr_gain
from quadlib.control.vehicle import MIXER, QuadrotorParams
from quadlib.geometry import kernels
from quadlib.geometry.quaternion import as_unit_quaternions, quat_conjugate
from quadlib.validation import as_finite_number, as_instance, as_matrix, as_positive, as_vector

__all__ = ["AltitudePid", "AttitudePid", "attitude_error", "attitude_pid_gains", "tilt_angle"]


def tilt_angle(q_nb) -> float:
    """The angle between body z and the vertical [rad], ``arccos(1 − 2(q₁² + q₂²))`` (E33)."""
    q = as_unit_quaternions("q_nb", q_nb)
    if q.shape != (4,):
        raise ValueError(f"q_nb: expected one quaternion of shape (4,), got {q.shape}")
    return _tilt(q)


def _tilt(q):
    return float(np.arccos(np.clip(1.0 - 2.0 * (q[1] ** 2 + q[2] ** 2), -1.0, 1.0)))


def attitude_error(q_hat, q_ref) -> np.ndarray:
    """The body-frame attitude error ``θ(q̌⁻¹ ⊗ q̂)`` [rad] (E34): the turn from the reference to the
    estimate, in the body's own axes."""
    q_hat, q_ref = as_unit_quaternions("q_hat", q_hat), as_unit_quaternions("q_ref", q_ref)
    if q_hat.shape != (4,) or q_ref.shape != (4,):
        raise ValueError(f"q_hat, q_ref: expected one quaternion each, shape (4,), got {q_hat.shape}, {q_ref.shape}")
    return _error(q_hat, q_ref)


def _error(q_hat, q_ref):
    e = kernels.multiply(quat_conjugate(q_ref), q_hat)
    e = e if e[0] >= 0.0 else -e  # the shorter of the two turns
    half_sin = float(np.linalg.norm(e[1:]))
    return e[1:] * (2.0 * np.arctan2(half_sin, e[0]) / half_sin) if half_sin > 1e-12 else 2.0 * e[1:]


@dataclass
class AltitudePid:
    """Eq. (3.2): ``T_z = c_p (ŝ − š) + c_i ∫(ŝ − š) dt + c_d (v̂ − v̌) + T₀`` [N], heights up.

    ``gains`` from :func:`~quadlib.control.altitude_pid_gains` (negative, E35); ``hover_thrust_n``
    is ``T₀``. Call :meth:`thrust` once per control step.
    """

    gains: AltitudeGains
    hover_thrust_n: float
    integral: float = 0.0

    def __post_init__(self):
        if not isinstance(self.gains, AltitudeGains) or not all(np.isfinite(self.gains)):
            raise TypeError(f"AltitudePid.gains: expected finite AltitudeGains, got {self.gains!r}")
        self.hover_thrust_n = as_positive("AltitudePid.hover_thrust_n", self.hover_thrust_n)
        self.integral = as_finite_number("AltitudePid.integral", self.integral)

    def thrust(self, s_hat: float, v_hat: float, s_ref: float, v_ref: float, dt: float) -> float:
        error = s_hat - s_ref
        self.integral += error * dt
        g = self.gains
        return g.c_p * error + g.c_i * self.integral + g.c_d * (v_hat - v_ref) + self.hover_thrust_n


def attitude_pid_gains(params: QuadrotorParams, q_angle: float = 4.0, q_rate: float = 1.0, q_integral: float = 1.0,
                       r: float = 1.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``C_p, C_i, C_d`` (3 × 3, diagonal, negative) of eq. (3.11) from an LQR per axis, as Kesten
    suggests when the inertia is known (§3.2): for each axis the double integrator
    ``θ̈ = b u`` with ``b = 2l/I_x, 2l/I_y`` (two motors, one arm each) and ``4k/I_z`` (four drag
    torques), an integral state, ``Q = diag(q_integral, q_angle, q_rate)`` and ``R = r`` [per N²]."""
    params = as_instance("params", params, QuadrotorParams)
    for name, value in (("q_angle", q_angle), ("q_rate", q_rate), ("q_integral", q_integral), ("r", r)):
        as_positive(name, value)
    inertia = np.broadcast_to(np.asarray(params.inertia_kg_m2, dtype=float), (3,))
    b = np.array([2 * params.arm_m, 2 * params.arm_m, 4 * params.drag_torque_m]) / inertia
    gains = np.empty((3, 3))
    for axis in range(3):
        A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
        K = lqr_gain(A, np.array([[0.0], [0.0], [b[axis]]]), np.diag([q_integral, q_angle, q_rate]), [[r]])[0]
        gains[axis] = -K  # integral, proportional, derivative
    return np.diag(gains[:, 1]), np.diag(gains[:, 0]), np.diag(gains[:, 2])


@dataclass
class AttitudePid:
    """Eqs. (3.8)–(3.11) with E33, E34 and E36: motor thrusts ``(front, right, rear, left)`` [N] from
    the vertical thrust the altitude controller asks for and the attitude error.

    ``T = (1, 1, 1, 1) T_z / (4 cos α) + M (C_p θ + C_i ∫θ dt + C_d (ω̂ − ω̌))``.
    """

    C_p: np.ndarray
    C_i: np.ndarray
    C_d: np.ndarray
    integral: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        for name in ("C_p", "C_i", "C_d"):
            setattr(self, name, as_matrix(f"AttitudePid.{name}", getattr(self, name), (3, 3)))
        self.integral = as_vector("AttitudePid.integral", self.integral, 3)

    def thrusts(self, thrust_z: float, q_hat, omega_hat, q_ref, omega_ref, dt: float) -> np.ndarray:
        theta = _error(q_hat, q_ref)
        self.integral = self.integral + theta * dt
        u = self.C_p @ theta + self.C_i @ self.integral + self.C_d @ (np.asarray(omega_hat) - omega_ref)
        mean = thrust_z / (4.0 * max(np.cos(_tilt(q_hat)), 0.2))  # no more than 5x past 78°
        return mean + MIXER @ u
