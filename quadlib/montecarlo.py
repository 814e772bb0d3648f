"""Monte Carlo ground truth for one Gaussian through a nonlinear function, and for one update.

Used to judge the EKF's linearisation and the UKF's unscented transform (chapters 03–04):
with enough samples, these are the exact answers up to sampling noise.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .model import Sensor
from .validation import as_covariance, as_rng, as_vector

__all__ = ["Moments", "importance_posterior", "propagate_samples"]


class Moments(NamedTuple):
    """Mean ``(k,)`` and covariance ``(k, k)`` of a sample set."""

    mean: np.ndarray
    cov: np.ndarray


def _samples(mu, P, n_samples: int, rng) -> np.ndarray:
    mu = as_vector("mu", mu)
    P = as_covariance("P", P, mu.size)
    if not isinstance(n_samples, (int, np.integer)) or n_samples < 2:
        raise ValueError(f"n_samples: expected an int >= 2, got {n_samples!r}")
    return as_rng(rng).multivariate_normal(mu, P, size=int(n_samples), method="eigh")


def propagate_samples(f, mu, P, n_samples: int, rng) -> tuple[Moments, np.ndarray]:
    """Push ``n_samples`` draws of ``N(mu, P)`` through ``f`` (vectorised over rows).

    Returns the sample mean and covariance of ``f(x)`` and the ``(n_samples, k)`` outputs.
    ``f`` must accept an ``(n_samples, n)`` array and return ``(n_samples,)`` or ``(n_samples, k)``.
    """
    y = np.asarray(f(_samples(mu, P, n_samples, rng)), dtype=float)
    y = y.reshape(n_samples, -1)
    return Moments(y.mean(axis=0), np.atleast_2d(np.cov(y, rowvar=False))), y


def importance_posterior(sensor: Sensor, mu, P, z, n_samples: int, rng) -> Moments:
    """Bayes posterior mean and covariance for prior ``N(mu, P)`` and one sample ``z`` of ``sensor``.

    Prior draws are weighted by the Gaussian likelihood ``N(z; h(x), R)``; ``sensor.h`` must
    accept an ``(n_samples, n)`` array and return ``(n_samples, k)`` (or ``(n_samples,)`` for k = 1).
    """
    x = _samples(mu, P, n_samples, rng)
    z = sensor.check_measurement(z)
    r = z - np.asarray(sensor.h(x), dtype=float).reshape(n_samples, sensor.dim_z)
    log_w = -0.5 * np.einsum("ij,jk,ik->i", r, np.linalg.inv(sensor.R), r)
    w = np.exp(log_w - log_w.max())
    w /= w.sum()
    mean = w @ x
    d = x - mean
    return Moments(mean, d.T @ (w[:, None] * d))
