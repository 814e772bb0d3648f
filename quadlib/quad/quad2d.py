"""The 2D quadrotor of Tellex et al. §6: lateral motion by rolling, sideways range to a wall.

State ``x = [φ, ẏ, y]`` (eq. 26): roll angle [rad], lateral velocity [m/s] and position [m];
input ``u = [φ_cmd]`` (eq. 27), the commanded roll, which the vehicle reaches within one step.
A range sensor looks along +y at a wall at ``y = wall_y`` (eq. 33); when the vehicle rolls, the
beam tilts with it and the range grows as ``1 / cos φ``.

.. math::

    g(x, u, \\Delta t) = \\begin{bmatrix} u_\\phi \\\\ \\dot y + g_0 \\tan\\phi\\,\\Delta t
        \\\\ y + \\dot y\\,\\Delta t \\end{bmatrix}, \\qquad
    h(x) = \\frac{\\text{wall}_y - y}{\\cos \\phi}

Source: Tellex et al. §6, eqs. (26)–(35). Differs from the source (erratum E9): eq. (28) writes
the velocity row as ``ẏ - sin(φ) Δt``, which has units of seconds, not m/s, and leaves gravity
out. A quadrotor that holds its height while rolled by φ needs thrust ``m g₀ / cos φ``, whose
horizontal part accelerates it by ``g₀ tan φ``; in FRD/NED a positive roll (right side down)
pushes it towards +y, so the sign is +. ``lateral_accel="seed"`` gives the printed
``-sin φ`` for comparison.
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import G0
from quadlib.model import Model, Sensor
from quadlib.validation import as_finite_number, as_positive

__all__ = ["quad2d_model", "quad2d_range_sensor"]


def quad2d_model(accel_sigma_m_s2: float, roll_sigma_rad: float, lateral_accel: str = "physics") -> Model:
    """Tellex §6 transition model with white process noise.

    Parameters
    ----------
    accel_sigma_m_s2 : float
        Standard deviation of the unmodelled lateral acceleration [m/s²] held over a step
        (gusts); enters ``ẏ`` and ``y`` as in the 1D model.
    roll_sigma_rad : float
        Standard deviation of the achieved roll around the command [rad], per step.
    lateral_accel : {"physics", "seed"}
        ``"physics"``: ``+g₀ tan φ`` (default); ``"seed"``: ``-sin φ`` as printed in eq. (28).
    """
    sa = as_positive("accel_sigma_m_s2", accel_sigma_m_s2)
    sr = as_positive("roll_sigma_rad", roll_sigma_rad)
    if lateral_accel == "physics":
        def accel(phi):
            return G0 * np.tan(phi)

        def daccel(phi):
            return G0 / np.cos(phi) ** 2
    elif lateral_accel == "seed":
        def accel(phi):
            return -np.sin(phi)

        def daccel(phi):
            return -np.cos(phi)
    else:
        raise ValueError(f"lateral_accel: expected 'physics' or 'seed', got {lateral_accel!r}")

    def g(x, u, dt):  # x: one state (3,) or a stack (M, 3)
        x = np.asarray(x, dtype=float)
        phi, ydot, y = x[..., 0], x[..., 1], x[..., 2]
        return np.stack([np.full_like(phi, u[0]), ydot + accel(phi) * dt, y + ydot * dt], axis=-1)

    def G(x, u, dt):
        x = np.asarray(x, dtype=float)
        J = np.zeros(x.shape[:-1] + (3, 3))
        J[..., 1, 0] = daccel(x[..., 0]) * dt
        J[..., 1, 1] = J[..., 2, 2] = 1.0
        J[..., 2, 1] = dt
        return J

    def Q(dt):
        w = np.array([0.0, dt, 0.5 * dt**2])
        return sa**2 * np.outer(w, w) + np.diag([sr**2, 0.0, 0.0])

    return Model(state_names=("phi [rad]", "ydot [m/s]", "y [m]"), input_names=("phi_cmd [rad]",),
                 g=g, G=G, Q=Q, name=f"quad2d ({lateral_accel})", vectorized=True)


def quad2d_range_sensor(sigma_m: float, wall_y_m: float = 5.0, rate_hz: float | None = None) -> Sensor:
    """Sideways range to the wall, ``r = (wall_y - y) / cos φ`` (eqs. 33, 35), noise σ [m].

    ``h`` and ``H`` also accept an ``(M, 3)`` stack of states: ``(M,)`` ranges, ``(M, 1, 3)`` Jacobians.
    """
    s = as_positive("sigma_m", sigma_m)
    wall = as_finite_number("wall_y_m", wall_y_m)

    def h(x):
        x = np.asarray(x, dtype=float)
        return np.atleast_1d((wall - x[..., 2]) / np.cos(x[..., 0]))

    def H(x):
        x = np.asarray(x, dtype=float)
        c = np.cos(x[..., 0])
        J = np.zeros(x.shape[:-1] + (1, 3))
        J[..., 0, 0] = (wall - x[..., 2]) * np.sin(x[..., 0]) / c**2
        J[..., 0, 2] = -1.0 / c
        return J

    return Sensor(name="range", measurement_names=("range [m]",), h=h, H=H,
                  R=np.full((1, 1), s**2), rate_hz=rate_hz, vectorized=True)
