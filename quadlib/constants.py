"""Physical constants and reference vectors, defined once (chapter 0 lists them).

Frames: NED earth frame (x north, y east, z down).
"""

from __future__ import annotations

import numpy as np

from quadlib.validation import as_angle, as_finite_number, as_positive

__all__ = ["G0", "GRAVITY_N", "SATURATED", "earth_field_ned"]

G0 = 9.80665
"""Standard gravity g₀ [m/s²] (the value the sources and PX4 use)."""

GRAVITY_N = np.array([0.0, 0.0, G0])
"""Gravity in NED [m/s²]: it points down, +z. An accelerometer at rest reads ``−R_nbᵀ GRAVITY_N``."""
GRAVITY_N.setflags(write=False)

SATURATED = 0.999
"""A gyro sample within 0.1 % of the full scale counts as clipped (:func:`~quadlib.imu.saturated_step_variance`)."""


def earth_field_ned(strength, inclination_rad, declination_rad=0.0) -> np.ndarray:
    """The Earth's magnetic field in NED, ``(3,)``, in the unit of ``strength``.

    .. math::

        m_n = |m| \\,[\\cos I \\cos D,\\; \\cos I \\sin D,\\; \\sin I]

    Parameters
    ----------
    strength : float
        Field magnitude (gauss, µT, or 1 for a unit vector).
    inclination_rad : float
        Dip ``I`` below the horizon [rad], positive down (about +1.1 in central Europe).
    declination_rad : float
        Angle ``D`` of magnetic north east of true north [rad].
    """
    s = as_positive("strength", strength)
    inc = as_finite_number("inclination_rad", inclination_rad)
    dec = as_angle("declination_rad", declination_rad)
    return s * np.array([np.cos(inc) * np.cos(dec), np.cos(inc) * np.sin(dec), np.sin(inc)])
