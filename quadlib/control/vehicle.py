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

The expressions are written once, compiled, in :mod:`quadlib.kernels.vehicle`: the closed loops of
:mod:`quadlib.control.closed_loop` take thousands of these steps per flight.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.constants import GRAVITY_N
from quadlib.geometry.quaternion import as_unit_quaternions
from quadlib.kernels import vehicle
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
    params = as_instance("params", params, QuadrotorParams)
    f, r, b, left = as_vector("thrusts", thrusts, 4)
    return np.array([params.arm_m * (left - r), params.arm_m * (f - b), params.drag_torque_m * (f + b - r - left)])


def _checked(params, X, thrust_cmd):
    X, thrust_cmd = as_vector("X", X, 17), as_vector("thrust_cmd", thrust_cmd, 4)
    if not X[6:10].any():
        raise ValueError(f"X: expected a non-zero attitude quaternion in X[6:10], got {X[6:10].tolist()}")
    # C-contiguous and writable, as the closed loops pass them: one compiled version of the kernels
    return np.require(X, requirements="CW"), np.require(thrust_cmd, requirements="CW"), *constants(params)


def quadrotor_derivative(params: QuadrotorParams, X, thrust_cmd) -> np.ndarray:
    """``Ẋ`` for commanded thrusts ``thrust_cmd`` (clipped to the motors' range)."""
    return vehicle.derivative(*_checked(params, X, thrust_cmd))


def quadrotor_step(params: QuadrotorParams, X, thrust_cmd, dt: float) -> np.ndarray:
    """One Runge–Kutta step of length ``dt`` with the command held."""
    X, thrust_cmd, *constants_ = _checked(params, X, thrust_cmd)
    return vehicle.step(X, thrust_cmd, as_positive("dt", dt), *constants_)


def hover_state(params: QuadrotorParams, height_m: float = 0.0, q_nb=(1.0, 0.0, 0.0, 0.0)) -> np.ndarray:
    """At rest at ``height_m`` above the origin with attitude ``q_nb``, motors at hover thrust."""
    params = as_instance("params", params, QuadrotorParams)
    height_m = as_finite_number("height_m", height_m)
    q_nb = as_unit_quaternions("q_nb", q_nb)
    if q_nb.shape != (4,):
        raise ValueError(f"q_nb: expected one quaternion of shape (4,), got {q_nb.shape}")
    return np.concatenate([[0.0, 0.0, -height_m], np.zeros(3), q_nb, np.zeros(3),
                           np.full(4, params.hover_thrust_n / 4.0)])


def constants(params: QuadrotorParams) -> tuple:
    """``params`` as the plain numbers the kernels of :mod:`quadlib.kernels.vehicle` take after the
    state and command: ``(mass, inertia (3,), arm, drag, max_thrust, motor_tau)``."""
    params = as_instance("params", params, QuadrotorParams)
    return (float(params.mass_kg), np.broadcast_to(np.asarray(params.inertia_kg_m2, dtype=float), (3,)).copy(),
            float(params.arm_m), float(params.drag_torque_m), float(params.max_thrust_n), float(params.motor_tau_s))
