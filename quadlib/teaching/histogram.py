"""Helpers for the histogram (grid) Bayes filter of chapter 02.

The belief over a scalar state is a vector of probabilities on a uniform
grid. filterpy's ``discrete_bayes.predict`` (shift + convolution) and
``discrete_bayes.update`` (likelihood × prior, normalised) do the filtering
(Tellex et al. §2, Algorithm 1); these functions build the kernel and the
likelihoods and summarise a belief.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import norm

from quadlib.validation import as_count, as_finite_array, as_finite_number, as_positive, as_probability

__all__ = ["belief_mean_std", "gaussian_belief", "gaussian_kernel", "gaussian_likelihood", "uniform_grid"]


def uniform_grid(low: float, high: float, cell: float) -> np.ndarray:
    """Cell centres from ``low`` to ``high`` (inclusive) spaced by ``cell``.

    Parameters
    ----------
    low, high : float
        Range of the state (e.g. height [m]), ``high > low``.
    cell : float
        Cell width, > 0.
    """
    cell = as_positive("cell", cell)
    low, high = as_finite_number("low", low), as_finite_number("high", high)
    if not high > low:
        raise ValueError(f"high: expected a value > low = {low!r}, got {high!r}")
    n = int(round((high - low) / cell)) + 1
    return low + cell * np.arange(n)


def _grid(grid) -> np.ndarray:
    grid = as_finite_array("grid", grid, ndim=1)
    if grid.size < 2 or np.any(np.diff(grid) <= 0):
        raise ValueError(f"grid: expected at least two strictly increasing cell centres, got {grid.tolist()[:5]}"
                         f"{' …' if grid.size > 5 else ''}")
    return grid


def gaussian_kernel(sigma_cells: float, half_width: int | None = None) -> np.ndarray:
    """Discretised zero-mean Gaussian of standard deviation ``sigma_cells`` (in cells).

    Each entry is the probability mass of its cell, so the kernel sums to 1.
    ``half_width`` defaults to ``ceil(5 sigma)``; the length is ``2 half_width + 1``.
    """
    s = as_positive("sigma_cells", sigma_cells)
    if half_width is not None:
        half_width = as_count("half_width", half_width, low=0)
    half = int(np.ceil(5 * s)) if half_width is None else half_width
    if half == 0:
        return np.ones(1)  # all mass stays in its cell
    return gaussian_belief(np.arange(-half, half + 1, dtype=float), 0.0, s)


def gaussian_belief(grid, mean: float, std: float) -> np.ndarray:
    """Belief with the mass of ``N(mean, std²)`` in each cell, normalised over the grid."""
    grid = _grid(grid)
    std, mean = as_positive("std", std), as_finite_number("mean", mean)
    half = 0.5 * (grid[1] - grid[0])
    mass = norm.cdf((grid + half - mean) / std) - norm.cdf((grid - half - mean) / std)
    if mass.sum() <= 0:
        raise ValueError(f"mean: N({mean:g}, {std:g}²) puts no mass on the grid [{grid[0]:g}, {grid[-1]:g}]")
    return mass / mass.sum()


def gaussian_likelihood(grid, z: float, sigma: float, outlier_probability: float = 0.0,
                        outlier_range: tuple[float, float] | None = None) -> np.ndarray:
    """Likelihood ``p(z | x)`` of a direct measurement at every grid cell.

    With ``outlier_probability = ε`` the sensor is a mixture: with probability
    ``1 - ε`` a Gaussian around the state, with probability ε a uniform value
    over ``outlier_range`` (default: the grid's range),

    .. math::  p(z | x) = (1-\\varepsilon)\\,\\mathcal N(z; x, \\sigma^2) + \\varepsilon / (b - a)

    Parameters
    ----------
    grid : (N,) cell centres
    z : float
        The measurement.
    sigma : float
        Standard deviation of the Gaussian part (same unit as the grid).
    outlier_probability : float in [0, 1)
    outlier_range : (a, b), optional
    """
    grid = _grid(grid)
    sigma, z = as_positive("sigma", sigma), as_finite_number("z", z)
    eps = as_probability("outlier_probability", outlier_probability, open_interval=False)
    if eps >= 1:
        raise ValueError(f"outlier_probability: expected a number in [0, 1), got {outlier_probability!r}")
    a, b = outlier_range if outlier_range is not None else (grid[0], grid[-1])
    if not b > a:
        raise ValueError(f"outlier_range: expected (a, b) with b > a, got {outlier_range!r}")
    return (1 - eps) * norm.pdf(z, loc=grid, scale=sigma) + eps / (b - a)


def belief_mean_std(grid, belief) -> tuple[float, float]:
    """Mean and standard deviation of a grid belief (treated as point masses at the centres)."""
    grid = _grid(grid)
    belief = as_finite_array("belief", belief, ndim=1)
    if belief.shape != grid.shape:
        raise ValueError(f"belief: expected shape {grid.shape} to match grid, got {belief.shape}")
    # filterpy's constant-mode predict shifts with scipy's cubic-spline ``shift``, which
    # leaves rounding-size negatives (seen: -1e-13 after renormalising); larger is an error
    if belief.sum() <= 0 or belief.min() < -1e-9 * belief.sum():
        raise ValueError(f"belief: expected non-negative probabilities with a positive sum, "
                         f"got min {belief.min():.3g} and sum {belief.sum():.3g}")
    p = np.clip(belief, 0.0, None)
    p = p / p.sum()
    mean = float(p @ grid)
    return mean, float(np.sqrt(p @ (grid - mean) ** 2))
