"""The four averaging estimators of Tellex et al. §1 (eqs. 1–4).

Each takes the samples ``z`` of shape ``(N,)`` (a directly observed scalar
state, e.g. height [m]) and returns the estimate after each sample, shape
``(N,)``. Sample indices here start at 1 (``z_1 … z_t``).
"""

from __future__ import annotations

import numpy as np

from quadlib.validation import as_finite_array, as_finite_number, as_probability

__all__ = ["batch_mean", "exponential_average", "half_average", "recursive_mean"]


def _samples(z) -> np.ndarray:
    z = as_finite_array("z", z, ndim=1)
    if z.size == 0:
        raise ValueError("z: expected at least one sample, got none")
    return z


def batch_mean(z) -> np.ndarray:
    """Mean of all samples so far, recomputed from scratch at every step.

    .. math::  \\hat x_t = \\frac{1}{t} \\sum_{i=1}^{t} z_i

    Source: Tellex et al. §1, eq. (1).
    Differs from the source: eq. (1) sums from 0 to t (t + 1 samples) but
    divides by t, and reuses t as the summation index; see the errata appendix.
    """
    z = _samples(z)
    return np.array([z[: t + 1].mean() for t in range(z.size)])


def recursive_mean(z) -> np.ndarray:
    """Running mean updated from the previous estimate only (constant memory).

    .. math::  \\hat x_t = \\frac{1}{t} \\left[ (t-1)\\,\\hat x_{t-1} + z_t \\right]

    Source: Tellex et al. §1, eq. (2).
    """
    z = _samples(z)
    out = np.empty_like(z)
    estimate = 0.0
    for t, zt in enumerate(z, start=1):
        estimate = ((t - 1) * estimate + zt) / t
        out[t - 1] = estimate
    return out


def exponential_average(z, alpha: float, x0: float | None = None) -> np.ndarray:
    """Exponentially weighted average; ``alpha`` is the weight of the *old* estimate.

    .. math::  \\hat x_t = \\alpha\\,\\hat x_{t-1} + (1 - \\alpha)\\, z_t

    Parameters
    ----------
    z : (N,) array_like
        Samples.
    alpha : float in [0, 1]
        Weight of the previous estimate: 0 follows the samples, values near 1
        smooth strongly (time constant ≈ ``dt / (1 - alpha)``).
    x0 : float, optional
        Estimate before the first sample; defaults to ``z[0]``.

    Source: Tellex et al. §1, eq. (4).
    """
    z = _samples(z)
    alpha = as_probability("alpha", alpha, open_interval=False)
    estimate = z[0] if x0 is None else as_finite_number("x0", x0)
    out = np.empty_like(z)
    for t, zt in enumerate(z):
        estimate = alpha * estimate + (1.0 - alpha) * zt
        out[t] = estimate
    return out


def half_average(z) -> np.ndarray:
    """Average of the previous estimate and the new sample: eq. (4) with ``alpha = 1/2``.

    .. math::  \\hat x_t = \\tfrac12 (\\hat x_{t-1} + z_t)

    Source: Tellex et al. §1, eq. (3).
    """
    return exponential_average(z, 0.5)
