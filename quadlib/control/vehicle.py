"""A rigid-body quadrotor in the "+" layout of Kesten's eq. (3.1): four motors front, right, rear,
left, each a first-order lag toward its commanded thrust, limited to ``[0, max_thrust_n]``.

State ``X`` (17): NED position ``p`` and velocity ``v``, attitude ``q_nb`` (scalar first), body rates
``ω`` (FRD) and the four motor thrusts ``T`` [N]. With arm length ``l`` and a rotor drag torque of
``k`` newton-metres per newton of thrust (front and rear spin one way, right and left the other):

.. math::

    \\dot p = v, \\quad \\dot v = g_n + R(q) \\begin{bmatrix}0\\\\0\\\\-\\textstyle\\sum T\\end{bmatrix}/m, \\quad
    \\dot q = \\tfrac12 q \\otimes [0, \\omega], \\quad
    \\dot\\omega = I^{-1}(\\tau - \\omega \\times I\\omega), \\quad \\dot T = (T_{cmd} - T)/\\tau_m

    \\tau = \\big(l (T_{left} - T_{right}),\\; l (T_{front} - T_{rear}),\\;
                 k (T_{front} + T_{rear} - T_{right} - T_{left})\\big)

(a motor at body position ``r`` pushes with ``(0, 0, −T)`` and turns the body by ``r × F``).
Integrated with the classical Runge–Kutta step; the quaternion is renormalised after each.

The closed loops of :mod:`quadlib.control.closed_loop` take thousands of these steps per flight,
so :func:`step_compiled` and :func:`derivative_compiled` write the same expressions once more as
numba-compiled code on plain numbers; ``tests/control/test_vehicle.py`` proves them equal, bit for
bit, to the readable :func:`quadrotor_derivative` and :func:`quadrotor_step`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from quadlib.constants import GRAVITY_N
from quadlib.geometry import kernels
from quadlib.geometry.quaternion import as_unit_quaternions
from quadlib.validation import as_finite_number, as_instance, as_positive, as_vector, check_fields

__all__ = ["MIXER", "QuadrotorParams", "hover_state", "motor_torques", "quadrotor_derivative", "quadrotor_step"]

MIXER = np.array([[0.0, 1.0, 1.0], [-1.0, 0.0, -1.0], [0.0, -1.0, 1.0], [1.0, 0.0, -1.0]])
"""Rows front, right, rear, left; columns roll, pitch, yaw: the thrust pattern that turns the body
positively about each axis (Kesten's matrix of eq. 3.11 — in FRD, with front and rear spinning so
that their drag turns the body to the right)."""


@dataclass(frozen=True)
class QuadrotorParams:
    """A quadrotor's physical constants. The mass is Kesten's (eq. 4.1); the rest are assumed for a
    450 mm frame (the thesis's Reely 450 airframe; its model, [Kesten] ref. [4], is not published).

    Parameters
    ----------
    mass_kg : float
    inertia_kg_m2 : (3,) tuple
        Principal moments about body x, y, z.
    arm_m : float
        Motor to centre.
    drag_torque_m : float
        Rotor drag torque per newton of thrust [N·m/N].
    motor_tau_s : float
        Time constant of a motor's thrust response.
    max_thrust_n : float
        The most one motor can push.
    """

    mass_kg: float = 1.1
    inertia_kg_m2: tuple = (0.012, 0.012, 0.022)
    arm_m: float = 0.225
    drag_torque_m: float = 0.016
    motor_tau_s: float = 0.03
    max_thrust_n: float = 6.0

    def __post_init__(self):
        check_fields(self, {"mass_kg": "positive", "inertia_kg_m2": "positive or 3", "arm_m": "positive",
                            "drag_torque_m": "positive", "motor_tau_s": "positive", "max_thrust_n": "positive"})

    @property
    def hover_thrust_n(self) -> float:
        """Total thrust that holds the weight, ``m g₀``."""
        return float(self.mass_kg * GRAVITY_N[2])


def motor_torques(params: QuadrotorParams, thrusts) -> np.ndarray:
    """Body torque ``τ`` [N·m] of motor thrusts ``(front, right, rear, left)``."""
    return _torques(as_instance("params", params, QuadrotorParams), as_vector("thrusts", thrusts, 4))


def _torques(params, thrusts):
    f, r, b, left = thrusts
    return np.array([params.arm_m * (left - r), params.arm_m * (f - b), params.drag_torque_m * (f + b - r - left)])


def _checked(params, X, thrust_cmd):
    params = as_instance("params", params, QuadrotorParams)
    X, thrust_cmd = as_vector("X", X, 17), as_vector("thrust_cmd", thrust_cmd, 4)
    if not X[6:10].any():
        raise ValueError(f"X: expected a non-zero attitude quaternion in X[6:10], got {X[6:10].tolist()}")
    return params, X, thrust_cmd


def quadrotor_derivative(params: QuadrotorParams, X, thrust_cmd) -> np.ndarray:
    """``Ẋ`` for commanded thrusts ``thrust_cmd`` (clipped to the motors' range)."""
    return _derivative(*_checked(params, X, thrust_cmd))


def _derivative(params, X, thrust_cmd):
    q, omega, T = X[6:10], X[10:13], X[13:17]
    inertia = np.asarray(params.inertia_kg_m2, dtype=float)
    f_n = kernels.dcm(q)[:, 2] * (-T.sum() / params.mass_kg)  # the thrust along −body z, in NED
    h = inertia * omega
    gyroscopic = np.array([omega[1] * h[2] - omega[2] * h[1], omega[2] * h[0] - omega[0] * h[2],
                           omega[0] * h[1] - omega[1] * h[0]])  # ω × Iω
    out = np.empty(17)
    out[0:3] = X[3:6]
    out[3:6] = GRAVITY_N + f_n
    out[6:10] = 0.5 * kernels.multiply(q, np.array([0.0, omega[0], omega[1], omega[2]]))
    out[10:13] = (_torques(params, T) - gyroscopic) / inertia
    out[13:17] = (np.clip(thrust_cmd, 0.0, params.max_thrust_n) - T) / params.motor_tau_s
    return out


def quadrotor_step(params: QuadrotorParams, X, thrust_cmd, dt: float) -> np.ndarray:
    """One Runge–Kutta step of length ``dt`` with the command held."""
    return _step(*_checked(params, X, thrust_cmd), as_positive("dt", dt))


def _step(params, X, thrust_cmd, dt):
    k1 = _derivative(params, X, thrust_cmd)
    k2 = _derivative(params, X + 0.5 * dt * k1, thrust_cmd)
    k3 = _derivative(params, X + 0.5 * dt * k2, thrust_cmd)
    k4 = _derivative(params, X + dt * k3, thrust_cmd)
    out = X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    out[6:10] = kernels.normalize(out[6:10])
    return out


def hover_state(params: QuadrotorParams, height_m: float = 0.0, q_nb=(1.0, 0.0, 0.0, 0.0)) -> np.ndarray:
    """At rest at ``height_m`` above the origin with attitude ``q_nb``, motors at hover thrust."""
    params = as_instance("params", params, QuadrotorParams)
    height_m = as_finite_number("height_m", height_m)
    q_nb = as_unit_quaternions("q_nb", q_nb)
    if q_nb.shape != (4,):
        raise ValueError(f"q_nb: expected one quaternion of shape (4,), got {q_nb.shape}")
    return np.concatenate([[0.0, 0.0, -height_m], np.zeros(3), q_nb, np.zeros(3),
                           np.full(4, params.hover_thrust_n / 4.0)])


# --- the same, compiled ---------------------------------------------------------------------------

def constants(params: QuadrotorParams) -> tuple:
    """``params`` as the plain numbers :func:`step_compiled` and :func:`derivative_compiled` take."""
    params = as_instance("params", params, QuadrotorParams)
    return (float(params.mass_kg), np.broadcast_to(np.asarray(params.inertia_kg_m2, dtype=float), (3,)).copy(),
            float(params.arm_m), float(params.drag_torque_m), float(params.max_thrust_n), float(params.motor_tau_s))


@njit(cache=True)
def derivative_compiled(X, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau):
    """:func:`quadrotor_derivative`, unchecked, with ``params`` as :func:`constants` gives them."""
    w, x, y, z = X[6], X[7], X[8], X[9]
    p, q, r = X[10], X[11], X[12]
    front, right, rear, left = X[13], X[14], X[15], X[16]
    push = -(front + right + rear + left) / mass
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    h0, h1, h2 = inertia[0] * p, inertia[1] * q, inertia[2] * r
    out = np.empty(17)
    out[0:3] = X[3:6]
    out[3] = GRAVITY_N_X + 2 * (x * z + w * y) * push
    out[4] = GRAVITY_N_Y + 2 * (y * z - w * x) * push
    out[5] = GRAVITY_N_Z + (ww - xx - yy + zz) * push
    out[6] = 0.5 * (w * 0.0 - x * p - y * q - z * r)
    out[7] = 0.5 * (w * p + x * 0.0 + y * r - z * q)
    out[8] = 0.5 * (w * q - x * r + y * 0.0 + z * p)
    out[9] = 0.5 * (w * r + x * q - y * p + z * 0.0)
    out[10] = (arm * (left - right) - (q * h2 - r * h1)) / inertia[0]
    out[11] = (arm * (front - rear) - (r * h0 - p * h2)) / inertia[1]
    out[12] = (drag * (front + rear - right - left) - (p * h1 - q * h0)) / inertia[2]
    for i in range(4):
        out[13 + i] = (min(max(thrust_cmd[i], 0.0), max_thrust) - X[13 + i]) / motor_tau
    return out


@njit(cache=True)
def step_compiled(X, thrust_cmd, dt, mass, inertia, arm, drag, max_thrust, motor_tau):
    """:func:`quadrotor_step`, unchecked, with ``params`` as :func:`constants` gives them."""
    k1 = derivative_compiled(X, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k2 = derivative_compiled(X + 0.5 * dt * k1, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k3 = derivative_compiled(X + 0.5 * dt * k2, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k4 = derivative_compiled(X + dt * k3, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    out = X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    q = out[6:10]
    out[6:10] = q / math.sqrt(q @ q)
    return out


GRAVITY_N_X, GRAVITY_N_Y, GRAVITY_N_Z = (float(v) for v in GRAVITY_N)
