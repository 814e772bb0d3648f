"""Standard figures: estimate vs truth with ±kσ bands, innovations, NEES/NIS vs χ² bounds, and the
ellipse of a two-dimensional Gaussian.

Every function draws on the ``ax`` it is given (or on a new figure when
``ax`` is None) and returns the axes; nothing touches pyplot's current-figure
state, so several figures can be built side by side.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from quadlib.analysis.metrics import chi2_interval
from quadlib.validation import as_count, as_finite_array, as_float_array, as_positive, as_times

__all__ = ["covariance_ellipse", "plot_consistency", "plot_covariance_ellipse", "plot_estimate", "plot_innovations"]


def _series(t, **named):
    """``t`` (times) and each named array of one value per time (NaN allowed), or a named error."""
    t = as_times("t", t)
    out = [t]
    for name, value in named.items():
        arr = None if value is None else as_float_array(name, value)
        if arr is not None and (arr.ndim == 0 or arr.shape[0] != t.size):
            raise ValueError(f"{name}: expected one value per time ({t.size}), got shape {arr.shape}")
        out.append(arr)
    return out


def _axes(ax, figsize=(7, 3)):
    if ax is None:
        _, ax = plt.subplots(figsize=figsize, layout="constrained")
    return ax


def plot_estimate(t, estimate, sigma=None, truth=None, *, k: float = 2.0, ax=None,
                  label: str = "estimate", ylabel: str = "", measurements=None):
    """Plot one state's estimate with a ±kσ band, the truth and optional measurements.

    Parameters
    ----------
    t : (N,) times [s]
    estimate : (N,) estimated values
    sigma : (N,) standard deviations, optional
    truth : (N,) true values, optional
    k : float
        Band half-width in standard deviations.
    measurements : tuple (t_z, z), optional
        Raw samples to show as dots.
    """
    t, estimate, sigma, truth = _series(t, estimate=estimate, sigma=sigma, truth=truth)
    k = as_positive("k", k)
    ax = _axes(ax)
    if measurements is not None:
        ax.plot(*measurements, ".", ms=2, color="0.6", label="measurements")
    if truth is not None:
        ax.plot(t, truth, color="k", lw=1.2, label="truth")
    line, = ax.plot(t, estimate, lw=1.2, label=label)
    if sigma is not None:
        ax.fill_between(t, estimate - k * sigma, estimate + k * sigma, color=line.get_color(),
                        alpha=0.25, lw=0, label=f"±{k:g}σ")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_innovations(t, innovation, S, *, k: float = 2.0, ax=None, ylabel: str = "innovation"):
    """Plot scalar innovations with the ±k√S bounds they should mostly stay inside."""
    t, innovation, S = _series(t, innovation=innovation, S=S)
    k = as_positive("k", k)
    ax = _axes(ax)
    y = innovation.reshape(len(t), -1)[:, 0]
    s = np.sqrt(S.reshape(len(t), -1)[:, 0])
    ax.plot(t, y, ".", ms=3, label="innovation")
    ax.plot(t, k * s, "r--", lw=1, label=f"±{k:g}√S")
    ax.plot(t, -k * s, "r--", lw=1)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(ylabel)
    ax.legend(loc="best", fontsize="small")
    return ax


def plot_consistency(t, values, dof: int, *, n_runs: int = 1, probability: float = 0.95,
                     ax=None, name: str = "NEES"):
    """Plot NEES or NIS (averaged over ``n_runs``) against its two-sided χ² interval."""
    t, values = _series(t, values=values)
    low, high = chi2_interval(dof, n_runs, probability)
    ax = _axes(ax)
    ax.plot(t, values, lw=1, label=name if n_runs == 1 else f"mean {name} ({n_runs} runs)")
    ax.axhline(low, color="r", ls="--", lw=1, label=f"{probability:.0%} χ² interval")
    ax.axhline(high, color="r", ls="--", lw=1)
    ax.axhline(dof, color="0.4", ls=":", lw=1, label=f"expected = {dof}")
    ax.set_xlabel("t [s]")
    ax.set_ylabel(name)
    ax.legend(loc="best", fontsize="small")
    return ax


def covariance_ellipse(mean, cov, k: float = 2.0, points: int = 101) -> np.ndarray:
    """The boundary of the k-sigma ellipse of a 2D Gaussian, (points, 2).

    The points :math:`x` with :math:`(x - \\mu)^\\top P^{-1} (x - \\mu) = k^2`: the unit circle
    stretched by the square roots of the eigenvalues of ``cov`` along its eigenvectors,
    :math:`x = \\mu + k\\,V \\Lambda^{1/2} [\\cos t, \\sin t]^\\top`.

    Parameters
    ----------
    mean : (2,) centre
    cov : (2, 2) symmetric positive semi-definite covariance
    k : float
        Half-axes in standard deviations (k = 2 holds about 86 % of the probability in 2D).
    points : int
        Number of points on the closed boundary (the last repeats the first; with the default 101
        the ends of both axes are among them).
    """
    mu = as_finite_array("mean", mean)
    P = as_finite_array("cov", cov)
    if mu.shape != (2,):
        raise ValueError(f"mean: expected shape (2,), got {mu.shape}")
    if P.shape != (2, 2) or not np.allclose(P, P.T, rtol=1e-9, atol=1e-12):
        raise ValueError(f"cov: expected a symmetric (2, 2) matrix, got {P.tolist() if P.size <= 4 else P.shape}")
    values, vectors = np.linalg.eigh(P)
    if values.min() < -1e-12 * max(1.0, abs(values.max())):
        raise ValueError(f"cov: expected a positive semi-definite matrix, got eigenvalues {values.tolist()}")
    k, n = as_positive("k", k), as_count("points", points)
    if n < 3:
        raise ValueError(f"points: expected at least 3, got {n}")
    angle = np.linspace(0.0, 2.0 * np.pi, n)
    circle = np.vstack([np.cos(angle), np.sin(angle)])
    return (mu[:, None] + k * vectors @ (np.sqrt(np.clip(values, 0.0, None))[:, None] * circle)).T


def plot_covariance_ellipse(mean, cov, *, k: float = 2.0, ax=None, label: str | None = None, **style):
    """Draw the k-sigma ellipse of a 2D Gaussian (:func:`covariance_ellipse`) and its centre on ``ax``.

    ``style`` goes to matplotlib's ``plot`` (``color``, ``lw``, ``ls`` …). Returns the axes.
    """
    boundary = covariance_ellipse(mean, cov, k)
    ax = _axes(ax, figsize=(4, 4))
    line, = ax.plot(boundary[:, 0], boundary[:, 1], label=label, **style)
    ax.plot(*np.asarray(mean, dtype=float), "+", color=line.get_color())
    return ax
