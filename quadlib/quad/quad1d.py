"""The 1D quadrotor of Tellex et al. §5: vertical motion only, acceleration input, downward range.

State ``x = [ż, z]`` (eq. 11) in the source's order: ``z`` is the height above the ground
[m], positive *up* (``z = -z_NED``; the range sensor looks down at the ground ``z = 0``), and
``ż`` its rate [m/s]. The input ``u = [z̈]`` (eq. 12) sets the vertical acceleration [m/s²]
directly (thrust minus gravity, up positive).

.. math::

    g(x, u, \\Delta t) = \\begin{bmatrix} 1 & 0 \\\\ \\Delta t & 1 \\end{bmatrix} x
        + \\begin{bmatrix} \\Delta t \\\\ 0 \\end{bmatrix} u, \\qquad
    h(x) = \\begin{bmatrix} 0 & 1 \\end{bmatrix} x

Source: Tellex et al. §5, eqs. (11)–(25). Differs from the source: eq. (13) prints the velocity
row as ``x_z + z̈ Δt`` (position instead of velocity); eqs. (14) and (17) are right and are used
here (erratum E8). The process noise, which the source leaves open, is a white acceleration
disturbance of standard deviation ``accel_sigma_m_s2`` entering as the input does, so that
``Q = σ² B Bᵀ`` plus the position share ``Δt²/2`` of exact integration (see :func:`quad1d_model`).
"""

from __future__ import annotations

import numpy as np

from quadlib.model import Model, Sensor
from quadlib.sim.trajectories import piecewise_constant
from quadlib.validation import as_positive

__all__ = ["climb_input", "quad1d_model", "quad1d_range_sensor"]


def quad1d_model(accel_sigma_m_s2: float) -> Model:
    """Tellex §5 transition model (eq. 14) with white-acceleration process noise.

    Parameters
    ----------
    accel_sigma_m_s2 : float
        Standard deviation of the unmodelled vertical acceleration [m/s²], held over each step.

    Notes
    -----
    An acceleration error ``a`` held for ``Δt`` changes the rate by ``a Δt`` and the height by
    ``a Δt²/2``, so ``Q = σ² [Δt, Δt²/2]ᵀ [Δt, Δt²/2]`` (rank one, like any single noise source).
    """
    s = as_positive("accel_sigma_m_s2", accel_sigma_m_s2)

    def g(x, u, dt):
        return np.array([x[0] + u[0] * dt, x[1] + x[0] * dt])

    def G(x, u, dt):
        return np.array([[1.0, 0.0], [dt, 1.0]])

    def B(x, u, dt):
        return np.array([[dt], [0.0]])

    def Q(dt):
        w = np.array([dt, 0.5 * dt**2])
        return s**2 * np.outer(w, w)

    return Model(state_names=("zdot [m/s]", "z [m]"), input_names=("zddot [m/s^2]",),
                 g=g, G=G, B=B, Q=Q, name="quad1d")


def quad1d_range_sensor(sigma_m: float, rate_hz: float | None = None) -> Sensor:
    """Downward range to the ground, ``r = z`` (Tellex §5.2, eqs. 19–25), noise σ [m]."""
    s = as_positive("sigma_m", sigma_m)
    return Sensor(name="range", measurement_names=("range [m]",),
                  h=lambda x: x[1:2].copy(), H=lambda x: np.array([[0.0, 1.0]]),
                  R=np.full((1, 1), s**2), rate_hz=rate_hz)


def climb_input(t) -> np.ndarray:
    """The commanded vertical acceleration of chapters 6 and 8, ``(N, 1)`` [m/s²] at times ``t``:
    hover for 1 s, climb (+1 m/s² for 2 s, −1 for 2 s), hold, descend (−0.5 for 2 s, +0.5 for 2 s),
    then hover."""
    return piecewise_constant(t, [1, 3, 5, 10, 12, 14], [1.0, -1.0, 0.0, -0.5, 0.5, 0.0])[:, None]
