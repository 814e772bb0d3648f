"""The kernels the compiled engine can call, and the switches that call them by number.

numba caches a compiled loop only if everything it calls is a global function known when it is
compiled: a function passed as an argument makes the loop uncacheable (about 5 s of compile in
every process). So the engine's loop (:mod:`quadlib.engine.loop`) calls one switch per role —
:func:`transition` for a model's ``g``, :func:`measure` for a sensor's ``h`` … — with the kernel's
number in :data:`TABLES`, and each switch calls that kernel. The loop and the switches are
compiled once, cached, and serve every model whose functions are listed here.

A kernel joins by appending it to its role's table and a branch with the next number to that
role's switch; ``tests/engine/test_dispatch.py`` checks that each number calls its table entry.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels import attitude as att
from quadlib.kernels import fixedwing, ins, kesten, quad3d

__all__ = ["TABLES"]

TABLES = {
    "g": (att.attitude_bias_step, kesten.quaternion_step, kesten.orientation_vector_step, ins.strapdown_step,
          quad3d.quad3d_step),
    "G": (att.attitude_error_jacobian, att.attitude_step_jacobian, att.identity_jacobian, ins.strapdown_error_jacobian,
          quad3d.quad3d_jacobian),
    "Q": (att.gyro_noise, ins.strapdown_noise, quad3d.quad3d_noise),
    "input_noise": (att.gyro_input_noise,),
    "state_add": (att.attitude_bias_add, kesten.rotation_blocks_add),
    "residual_x": (att.attitude_bias_difference, kesten.rotation_blocks_difference, att.angle_difference),
    "add_jacobian": (att.attitude_bias_add_jacobian,),
    "normalize": (att.normalize_quaternion,),
    "normalize_jacobian": (att.normalize_quaternion_jacobian,),
    "h": (att.body_vector, att.field_heading, att.linear_map, kesten.quaternion_rotvec, fixedwing.airspeed_accel,
          fixedwing.unit_field),
    "H": (att.body_vector_H, att.heading_only_H, att.tilt_aware_heading_H, att.linear_map_H, fixedwing.airspeed_accel_H,
          fixedwing.unit_field_H),
    "residual": (att.wrapped_difference, kesten.nearest_orientation, kesten.same_sign_quaternion,
                 kesten.rotvec_turn, kesten.turn_between),
    "mean": (att.circular_mean,),
}
"""Role → the kernels of that role, numbered by position (a model's ``-1``: the role is unused)."""

IDENTITY = TABLES["G"].index(att.identity_jacobian)
"""The number of ``G = I``, whose ``G P Gᵀ`` the engine skips (it is ``P`` exactly)."""


@njit(cache=True, inline="always")
def transition(kind, x, u, dt, p):
    """``g(x, u, dt)``."""
    if kind == 0:
        return att.attitude_bias_step(x, u, dt, p)
    if kind == 1:
        return kesten.quaternion_step(x, u, dt, p)
    if kind == 2:
        return kesten.orientation_vector_step(x, u, dt, p)
    if kind == 3:
        return ins.strapdown_step(x, u, dt, p)
    return quad3d.quad3d_step(x, u, dt, p)


@njit(cache=True, inline="always")
def jacobian(kind, x, u, dt, p):
    """``G(x, u, dt)``."""
    if kind == 0:
        return att.attitude_error_jacobian(x, u, dt, p)
    if kind == 1:
        return att.attitude_step_jacobian(x, u, dt, p)
    if kind == 2:
        return att.identity_jacobian(x, u, dt, p)
    if kind == 3:
        return ins.strapdown_error_jacobian(x, u, dt, p)
    return quad3d.quad3d_jacobian(x, u, dt, p)


@njit(cache=True, inline="always")
def process_noise(kind, dt, p):
    """``Q(dt)``."""
    if kind == 0:
        return att.gyro_noise(dt, p)
    if kind == 1:
        return ins.strapdown_noise(dt, p)
    return quad3d.quad3d_noise(dt, p)


@njit(cache=True, inline="always")
def input_noise(kind, u, dt, p):
    """``(added, M)``: the noise the input ``u`` adds over ``dt``."""
    return att.gyro_input_noise(u, dt, p)


@njit(cache=True, inline="always")
def state_add(kind, x, d, p):
    """``x ⊞ d``."""
    if kind == 0:
        return att.attitude_bias_add(x, d, p)
    return kesten.rotation_blocks_add(x, d, p)


@njit(cache=True, inline="always")
def residual_x(kind, x1, x0, p):
    """``x₁ ⊟ x₀``."""
    if kind == 0:
        return att.attitude_bias_difference(x1, x0, p)
    if kind == 1:
        return kesten.rotation_blocks_difference(x1, x0, p)
    return att.angle_difference(x1, x0, p)


@njit(cache=True, inline="always")
def add_jacobian(kind, x, p):
    """``∂(x ⊞ δ)/∂δ`` at 0."""
    return att.attitude_bias_add_jacobian(x, p)


@njit(cache=True, inline="always")
def normalize(kind, x, p):
    """``x`` back on its manifold."""
    return att.normalize_quaternion(x, p)


@njit(cache=True, inline="always")
def normalize_jacobian(kind, x, p):
    """``∂normalize/∂x``."""
    return att.normalize_quaternion_jacobian(x, p)


@njit(cache=True, inline="always")
def measure(kind, x, c, p):
    """``h(x, c)``."""
    if kind == 0:
        return att.body_vector(x, c, p)
    if kind == 1:
        return att.field_heading(x, c, p)
    if kind == 2:
        return att.linear_map(x, c, p)
    if kind == 3:
        return kesten.quaternion_rotvec(x, c, p)
    if kind == 4:
        return fixedwing.airspeed_accel(x, c, p)
    return fixedwing.unit_field(x, c, p)


@njit(cache=True, inline="always")
def measurement_jacobian(kind, x, c, p):
    """``H(x, c)``."""
    if kind == 0:
        return att.body_vector_H(x, c, p)
    if kind == 1:
        return att.heading_only_H(x, c, p)
    if kind == 2:
        return att.tilt_aware_heading_H(x, c, p)
    if kind == 3:
        return att.linear_map_H(x, c, p)
    if kind == 4:
        return fixedwing.airspeed_accel_H(x, c, p)
    return fixedwing.unit_field_H(x, c, p)


@njit(cache=True, inline="always")
def residual(kind, z, z_hat, p):
    """The innovation ``z ⊖ ẑ``; kind ``-1`` is the plain difference."""
    if kind < 0:
        return z - z_hat
    if kind == 0:
        return att.wrapped_difference(z, z_hat, p)
    if kind == 1:
        return kesten.nearest_orientation(z, z_hat, p)
    if kind == 2:
        return kesten.same_sign_quaternion(z, z_hat, p)
    if kind == 3:
        return kesten.rotvec_turn(z, z_hat, p)
    return kesten.turn_between(z, z_hat, p)


@njit(cache=True, inline="always")
def mean(kind, Z, w, p):
    """A UKF's weighted mean of the sigma points ``Z``; kind ``-1`` is the plain ``w Z``."""
    if kind < 0:
        out = np.zeros(Z.shape[1])
        for r in range(Z.shape[0]):
            for j in range(Z.shape[1]):
                out[j] += w[r] * Z[r, j]
        return out
    return att.circular_mean(Z, w, p)


SWITCHES = {"g": transition, "G": jacobian, "Q": process_noise, "input_noise": input_noise, "state_add": state_add,
            "residual_x": residual_x, "add_jacobian": add_jacobian, "normalize": normalize,
            "normalize_jacobian": normalize_jacobian, "h": measure, "H": measurement_jacobian, "residual": residual,
            "mean": mean}
"""Role → its switch (for the test that each number calls its table entry)."""


def kind_of(kernel) -> int:
    """The number of ``kernel``'s function in its role's table, or ``-1`` if the engine does not know it."""
    table = TABLES[kernel.role]
    for i, f in enumerate(table):
        if f is kernel.function:
            return i
    return -1

