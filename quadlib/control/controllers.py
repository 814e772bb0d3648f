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

import math
from dataclasses import dataclass, field

import numpy as np

from quadlib.constants import G0
from quadlib.control.lqr import AltitudeGains, lqr_gain
from quadlib.control.vehicle import MIXER, QuadrotorParams
from quadlib.geometry.quaternion import as_unit_quaternions
from quadlib.kernels.quaternion import conjugate, from_dcm, multiply
from quadlib.validation import as_finite_number, as_instance, as_matrix, as_positive, as_vector

__all__ = ["AltitudePid", "AttitudePid", "PositionController", "attitude_error", "attitude_pid_gains",
           "thrust_attitude", "tilt_angle"]


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
    e = multiply(conjugate(q_ref), q_hat)
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


def thrust_attitude(accel_n, yaw_rad: float, mass_kg: float) -> tuple[np.ndarray, float]:
    """The attitude and vertical thrust that give the acceleration ``accel_n`` (NED) [m/s²] facing
    ``yaw_rad``: the rotors must push along ``F = m (a − g_n)``, so body z points along ``−F``, body x
    is the heading projected across it, and the vertical thrust is ``−F_z`` [N] (the differential
    flatness of chapter 11's flights, run backwards). Unchecked: called every control step."""
    fx, fy, fz = (mass_kg * (accel_n - np.array([0.0, 0.0, G0]))).tolist()
    norm = math.sqrt(fx * fx + fy * fy + fz * fz)
    b3 = (-fx / norm, -fy / norm, -fz / norm)
    hx, hy = math.cos(yaw_rad), math.sin(yaw_rad)
    b2 = (-b3[2] * hy, b3[2] * hx, b3[0] * hy - b3[1] * hx)  # b3 × heading, heading = (hx, hy, 0)
    n2 = math.sqrt(b2[0] ** 2 + b2[1] ** 2 + b2[2] ** 2)
    b2 = (b2[0] / n2, b2[1] / n2, b2[2] / n2)
    b1 = (b2[1] * b3[2] - b2[2] * b3[1], b2[2] * b3[0] - b2[0] * b3[2], b2[0] * b3[1] - b2[1] * b3[0])
    R = np.array([[b1[0], b2[0], b3[0]], [b1[1], b2[1], b3[1]], [b1[2], b2[2], b3[2]]])
    return from_dcm(R), -fz


@dataclass
class PositionController:
    """The cascade of a multirotor autopilot (PX4's multicopter position and attitude controllers
    have this shape): position error → velocity set-point (P, limited) → acceleration set-point
    (PI on the velocity error, plus the path's own acceleration) → the attitude and thrust that
    produce it (:func:`thrust_attitude`, the tilt limited) → :class:`AttitudePid` → motor thrusts.

    Parameters
    ----------
    attitude : AttitudePid
    mass_kg : float
    k_position, k_velocity, k_velocity_integral : float
        Gains [1/s], [1/s], [1/s²].
    max_speed_m_s : float
    max_tilt_rad : float
    """

    attitude: AttitudePid
    mass_kg: float
    k_position: float = 1.5
    k_velocity: float = 3.0
    k_velocity_integral: float = 0.5
    max_speed_m_s: float = 8.0
    max_tilt_rad: float = float(np.radians(35.0))
    integral: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self):
        self.attitude = as_instance("PositionController.attitude", self.attitude, AttitudePid)
        for name in ("mass_kg", "k_position", "k_velocity", "k_velocity_integral", "max_speed_m_s", "max_tilt_rad"):
            setattr(self, name, as_positive(f"PositionController.{name}", getattr(self, name)))
        self.integral = as_vector("PositionController.integral", self.integral, 3)

    def thrusts(self, p_hat, v_hat, q_hat, omega_hat, p_ref, v_ref, a_ref, yaw_ref: float, omega_ref,
                dt: float) -> np.ndarray:
        v_sp = v_ref + self.k_position * (p_ref - p_hat)
        speed = float(np.linalg.norm(v_sp))
        if speed > self.max_speed_m_s:
            v_sp = v_sp * (self.max_speed_m_s / speed)
        error = v_sp - v_hat
        self.integral = self.integral + error * dt
        a_sp = a_ref + self.k_velocity * error + self.k_velocity_integral * self.integral
        horizontal = float(np.hypot(a_sp[0], a_sp[1]))
        limit = np.tan(self.max_tilt_rad) * (G0 - a_sp[2])
        if horizontal > limit > 0.0:
            a_sp[:2] *= limit / horizontal
        q_sp, thrust_z = thrust_attitude(a_sp, yaw_ref, self.mass_kg)
        return self.attitude.thrusts(thrust_z, q_hat, omega_hat, q_sp, omega_ref, dt)
