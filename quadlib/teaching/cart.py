"""A cart on a straight track: the toy problem of chapters 05 and 06, before the first drone.

State ``x = [v, p]``: velocity [m/s] and position [m] along the track, velocity first as in the 1D
quadrotor of chapter 08 (Tellex et al. §5), so the two chapters read alike. The input ``u = [a]`` is
a commanded acceleration [m/s²] (zero for a cart that coasts), and an unmodelled acceleration of
standard deviation ``accel_sigma_m_s2``, held over each step, is the process noise:

.. math::

    x_k = \\begin{bmatrix} 1 & 0 \\\\ \\Delta t & 1 \\end{bmatrix} x_{k-1}
        + \\begin{bmatrix} \\Delta t \\\\ 0 \\end{bmatrix} u, \\qquad
    Q = \\sigma_a^2 \\gamma \\gamma^\\top, \\quad \\gamma = [\\Delta t,\\ \\Delta t^2 / 2]^\\top

It is the same double integrator as :func:`quadlib.quad.quad1d_model`, under the cart's names;
the sensors measure the position (:math:`H = [0\\ 1]`) or the speed (:math:`H = [1\\ 0]`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from quadlib.model import Model, Sensor
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.validation import as_positive

__all__ = ["cart_model", "cart_position_sensor", "cart_speed_sensor"]


def cart_model(accel_sigma_m_s2: float) -> Model:
    """The cart's transition model, state ``[v, p]``, input ``[a]`` (module documentation).

    Parameters
    ----------
    accel_sigma_m_s2 : float
        Standard deviation of the unmodelled acceleration [m/s²], held over each step.
    """
    return replace(quad1d_model(accel_sigma_m_s2), state_names=("v [m/s]", "p [m]"), input_names=("a [m/s^2]",),
                   name="cart")


def cart_position_sensor(sigma_m: float, rate_hz: float | None = None) -> Sensor:
    """A position sensor on the track (a laser range to the track's end, say): ``z = p + w``,
    ``w ~ N(0, sigma_m²)``, so ``H = [0 1]``."""
    return replace(quad1d_range_sensor(sigma_m, rate_hz), name="position", measurement_names=("p [m]",))


def cart_speed_sensor(sigma_m_s: float, rate_hz: float | None = None) -> Sensor:
    """A wheel odometer: ``z = v + w``, ``w ~ N(0, sigma_m_s²)``, so ``H = [1 0]``."""
    s = as_positive("sigma_m_s", sigma_m_s)
    return Sensor(name="speed", measurement_names=("v [m/s]",), h=lambda x: x[0:1].copy(),
                  H=lambda x: np.array([[1.0, 0.0]]), R=np.full((1, 1), s**2), rate_hz=rate_hz)
