"""A body-fixed downward rangefinder on a rolling drone: the slant range ``r = z / cos φ``.

State ``x = [z, φ]``: height above flat ground [m] (positive up) and roll [rad]. The beam is
fixed to the body, so when the drone rolls the beam tilts with it and hits the ground at the
slant distance ``z / cos φ`` (the same ``1 / cos`` as the 2D quadrotor's sideways sensor,
Tellex et al. §6, eq. 33). Chapters 06–07 use it to show where linearisation fails: at
``φ = 0`` the range's slope in ``φ`` is zero.
"""

from __future__ import annotations

import numpy as np

from quadlib.model import Sensor
from quadlib.validation import as_positive

__all__ = ["tilted_range_sensor"]


def tilted_range_sensor(sigma_m: float) -> Sensor:
    """Slant range ``r = z / cos φ`` with noise σ [m]; ``h`` also accepts stacked states ``(..., 2)``.

    .. math:: H = \\begin{bmatrix} 1/\\cos\\varphi & z \\tan\\varphi / \\cos\\varphi \\end{bmatrix}
    """
    s = as_positive("sigma_m", sigma_m)

    def h(x):
        x = np.asarray(x)
        return np.atleast_1d(x[..., 0] / np.cos(x[..., 1]))

    def H(x):
        c = np.cos(x[1])
        return np.array([[1.0 / c, x[0] * np.tan(x[1]) / c]])

    return Sensor(name="slant range", measurement_names=("r [m]",), h=h, H=H, R=np.full((1, 1), s**2))
