"""The quadrotor of :mod:`quadlib.control.vehicle` as numba kernels (:mod:`quadlib.kernels`): the
closed loops take thousands of these steps per flight. The vehicle's constants come as plain
numbers, ``(mass, inertia (3,), arm, drag, max_thrust, motor_tau)``, as
:func:`~quadlib.control.vehicle.constants` gives them.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.constants import GRAVITY_N

__all__: list[str] = []  # bound by quadlib.control.vehicle

GRAVITY_N_X, GRAVITY_N_Y, GRAVITY_N_Z = (float(v) for v in GRAVITY_N)


@njit(cache=True)
def derivative(X, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau):
    """``Ẋ`` of the state ``X`` (17) for commanded thrusts (clipped to ``[0, max_thrust]``)."""
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
def step(X, thrust_cmd, dt, mass, inertia, arm, drag, max_thrust, motor_tau):
    """One classical Runge–Kutta step of length ``dt``, the command held, the quaternion renormalised."""
    k1 = derivative(X, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k2 = derivative(X + 0.5 * dt * k1, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k3 = derivative(X + 0.5 * dt * k2, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    k4 = derivative(X + dt * k3, thrust_cmd, mass, inertia, arm, drag, max_thrust, motor_tau)
    out = X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    q = out[6:10]
    out[6:10] = q / math.sqrt(q @ q)
    return out
