"""Standard figures: estimate vs truth with ±kσ bands, innovations, NEES/NIS vs χ² bounds.

Every function draws on the ``ax`` it is given (or on a new figure when
``ax`` is None) and returns the axes; nothing touches pyplot's current-figure
state, so several figures can be built side by side.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from quadlib.analysis.metrics import chi2_interval
from quadlib.validation import as_float_array, as_positive, as_times

__all__ = ["plot_consistency", "plot_estimate", "plot_innovations"]


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
