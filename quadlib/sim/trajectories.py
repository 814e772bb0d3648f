"""Truth trajectories (deterministic profiles) used by the simulators."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from quadlib.constants import G0
from quadlib.samples import Samples
from quadlib.validation import as_count, as_finite_array, as_finite_number, as_positive, as_rng

__all__ = ["VerticalRun", "min_jerk", "piecewise_constant", "step_profile", "vertical_sine"]


def step_profile(t, t_step: float, before: float, after: float) -> np.ndarray:
    """A value that jumps from ``before`` to ``after`` at ``t_step``.

    Parameters
    ----------
    t : (N,) array_like
        Times [s].
    t_step : float
        Time of the jump [s]; samples with ``t >= t_step`` take ``after``.
    before, after : float
        Values before and after the jump (e.g. height [m]).

    Returns
    -------
    (N,) ndarray
    """
    t = as_finite_array("t", t, ndim=1)
    t_step, after, before = (as_finite_number(n, v) for n, v in (("t_step", t_step), ("after", after),
                                                                 ("before", before)))
    return np.where(t >= t_step, after, before)


def piecewise_constant(t, breakpoints, values) -> np.ndarray:
    """A profile that takes ``values[i]`` on ``[breakpoints[i], breakpoints[i+1])``.

    Before ``breakpoints[0]`` the profile is 0; after the last breakpoint it keeps the last
    value. Typical use: a control input such as an acceleration [m/s²] or a roll command [rad].

    Parameters
    ----------
    t : (N,) array_like
        Times [s].
    breakpoints : (K,) array_like
        Strictly increasing switching times [s].
    values : (K,) array_like
        Value from each breakpoint on.

    Returns
    -------
    (N,) ndarray
    """
    t = as_finite_array("t", t, ndim=1)
    b = as_finite_array("breakpoints", breakpoints, ndim=1)
    v = as_finite_array("values", values, ndim=1)
    if b.shape != v.shape or b.size == 0:
        raise ValueError(f"values: expected one value per breakpoint ({b.size}), got {v.size}")
    if np.any(np.diff(b) <= 0):
        raise ValueError(f"breakpoints: expected strictly increasing times, got {b.tolist()}")
    i = np.searchsorted(b, t, side="right") - 1
    return np.where(i >= 0, v[np.clip(i, 0, None)], 0.0)


def min_jerk(s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Minimum-jerk blend on ``s`` ∈ [0, 1] and its first two derivatives with respect to ``s``
    (all zero at both ends): ``10 s³ − 15 s⁴ + 6 s⁵``. Values outside [0, 1] are clipped."""
    s = np.clip(as_finite_array("s", s), 0.0, 1.0)
    return 10 * s**3 - 15 * s**4 + 6 * s**5, 30 * s**2 - 60 * s**3 + 30 * s**4, 60 * s - 180 * s**2 + 120 * s**3


class VerticalRun(NamedTuple):
    """A vertical motion: times ``t`` [s], true altitude [m, up], the up specific force ``a_z``
    [m/s²] an accelerometer reads (about +g₀ at rest, with noise), and barometer samples [m]."""

    t: np.ndarray
    altitude_m: np.ndarray
    a_z: np.ndarray
    baro: Samples


def vertical_sine(duration_s: float, rng, amplitude_m: float = 5.0, period_s: float = 20.0,
                  dt: float = 0.004, accel_sigma_m_s2: float = 0.06, baro_sigma_m: float = 0.39,
                  baro_every: int = 10) -> VerticalRun:
    """Altitude ``A sin(2π t / T)`` sampled every ``dt``, with the accelerometer's up specific force
    ``g₀ + s̈`` and a barometer every ``baro_every`` samples (Kesten's sensors by default: 250 Hz,
    σ 0.06 m/s²; 25 Hz, σ 0.39 m). The noise is drawn accelerometer first, then barometer."""
    rng = as_rng(rng)
    dt = as_positive("dt", dt)
    t = np.arange(int(as_positive("duration_s", duration_s) / dt) + 1) * dt
    w = 2 * np.pi / as_positive("period_s", period_s)
    amplitude = as_finite_number("amplitude_m", amplitude_m)
    altitude = amplitude * np.sin(w * t)
    a_z = G0 - amplitude * w**2 * np.sin(w * t) + rng.normal(0.0, as_positive("accel_sigma_m_s2", accel_sigma_m_s2),
                                                              t.size)
    baro_every = as_count("baro_every", baro_every)
    k = np.arange(0, t.size, baro_every)
    baro = altitude[k] + rng.normal(0.0, as_positive("baro_sigma_m", baro_sigma_m), k.size)
    return VerticalRun(t, altitude, a_z, Samples(t[k], baro))
