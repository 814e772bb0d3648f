"""Height of a hovering drone commanded by a vertical velocity (chapters 01–02).

State ``x = [h]`` (height above ground [m], positive *up*: ``h = -z_NED``),
input ``u = [v]`` (commanded climb rate [m/s]). The drone's real climb rate
differs from the command by white noise of standard deviation
``velocity_sigma_m_s``, so over one step

.. math::  h_k = h_{k-1} + v\\,\\Delta t + w, \\qquad w \\sim \\mathcal N(0, (\\sigma_v \\Delta t)^2)

This is the simplest instance of Tellex et al. §2's predict step; the range
sensor looks straight down and measures ``h`` directly.
"""

from __future__ import annotations

import numpy as np

from quadlib.model import Model, Sensor
from quadlib.validation import as_positive

__all__ = ["height_model", "range_sensor"]


def height_model(velocity_sigma_m_s: float) -> Model:
    """Constant-commanded-velocity height model.

    Parameters
    ----------
    velocity_sigma_m_s : float
        Standard deviation of the actual climb rate around the command [m/s].
    """
    s = as_positive("velocity_sigma_m_s", velocity_sigma_m_s)
    return Model(
        state_names=("h [m]",),
        input_names=("v [m/s]",),
        g=lambda x, u, dt: x + u * dt,
        G=lambda x, u, dt: np.ones((1, 1)),
        B=lambda x, u, dt: np.full((1, 1), dt),
        Q=lambda dt: np.full((1, 1), (s * dt) ** 2),
        name="height",
    )


def range_sensor(sigma_m: float, rate_hz: float | None = None) -> Sensor:
    """Downward range sensor measuring the height: ``z = h + v``, ``v ~ N(0, sigma_m²)``."""
    s = as_positive("sigma_m", sigma_m)
    return Sensor(
        name="range",
        measurement_names=("range [m]",),
        h=lambda x: x[:1].copy(),
        H=lambda x: np.ones((1, 1)),
        R=np.full((1, 1), s**2),
        rate_hz=rate_hz,
    )
