"""Truth trajectories (deterministic profiles) used by the simulators."""

from __future__ import annotations

import numpy as np

from .validation import as_finite_array

__all__ = ["step_profile"]


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
    return np.where(t >= float(t_step), float(after), float(before))
