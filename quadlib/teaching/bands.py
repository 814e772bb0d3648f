"""NEES and NIS averaged over runs, drawn against their χ² band with readable axes.

A consistent filter's NEES (NIS) averaged over ``M`` runs is :math:`\\chi^2_{Mn}/M` distributed,
so it should stay inside the two-sided interval of :func:`~quadlib.analysis.metrics.chi2_interval`.
:func:`plot_chi2_band` draws that interval as a shaded band (not as two lines a legend can sit on)
and the expected value as a dotted line, and labels a logarithmic axis with plain numbers at a few
round values (0.1, 1, 10 …, or 1, 2, 5 … within a decade) instead of every minor tick. The artists
carry labels, so a caller collects them into one legend outside the axes
(``fig.legend(..., loc="outside upper center")``), where it cannot hide a curve.
"""

from __future__ import annotations

import numpy as np
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from quadlib.analysis.metrics import chi2_interval
from quadlib.validation import as_count, as_float_array, as_probability, as_times

__all__ = ["plot_chi2_band", "readable_log_axis"]

YSCALES = ("auto", "log", "linear")
SUBS = ((1.0,), (1.0, 2.0, 5.0), (1.0, 1.5, 2.0, 3.0, 5.0, 7.0), tuple(np.arange(1.0, 10.0)))


def readable_log_axis(ax, axis: str = "y"):
    """Give a logarithmic ``axis`` ("x" or "y") of ``ax`` a few round, plainly printed ticks.

    The labels are the coarsest of these that puts at least two of them in view: the powers of
    ten (0.01, 0.1, 1, 10 …); 1, 2 and 5 times them; 1, 1.5, 2, 3, 5 and 7 times them; every
    integer multiple. Minor ticks stay, unlabelled. Call it after the data are drawn (it reads the
    limits).
    Returns the axes.
    """
    if axis not in ("x", "y"):
        raise ValueError(f"axis: expected 'x' or 'y', got {axis!r}")
    if not hasattr(ax, "get_yscale"):
        raise TypeError(f"ax: expected matplotlib axes, got {type(ax).__name__}")
    scale = ax.get_xscale() if axis == "x" else ax.get_yscale()
    if scale != "log":
        raise ValueError(f"ax: expected a logarithmic {axis} axis, got a {scale!r} one")
    lo, hi = sorted(ax.get_xlim() if axis == "x" else ax.get_ylim())
    powers = 10.0 ** np.arange(np.floor(np.log10(lo)) - 1, np.ceil(np.log10(hi)) + 1)
    for subs in SUBS:  # the coarsest that puts at least two labelled ticks in view
        ticks = np.outer(powers, subs).ravel()
        if np.sum((ticks >= lo * (1 - 1e-9)) & (ticks <= hi * (1 + 1e-9))) >= 2:
            break
    target = ax.xaxis if axis == "x" else ax.yaxis
    target.set_major_locator(LogLocator(base=10.0, subs=subs))
    target.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    target.set_minor_locator(LogLocator(base=10.0, subs=np.arange(1.0, 10.0)))
    target.set_minor_formatter(NullFormatter())
    return ax


def consistency_verdict(value: float, band: tuple[float, float]) -> str:
    """"consistent" when a mean NEES ``value`` lies inside its χ² ``band``, else "over-confident"
    (above: the errors are larger than the filter claims) or "pessimistic" (below)."""
    if value > band[1]:
        return "over-confident"
    return "pessimistic" if value < band[0] else "consistent"


def plot_chi2_band(t, values, dof: int, *, n_runs: int = 1, probability: float = 0.95, ax=None,
                   name: str = "NEES", label: str | None = None, color: str = "C0", marker: str | None = None,
                   yscale: str = "auto", band_color: str = "C2"):
    """Draw a NEES or NIS series (averaged over ``n_runs``) over its ``probability`` χ² band.

    Parameters
    ----------
    t : (N,) times [s]
    values : (N,) the mean NEES or NIS at each time (NaN where there is none)
    dof : int
        Degrees of freedom of one value: the state dimension for NEES, the measurement's for NIS.
    n_runs : int
        Runs averaged into each value (the band narrows as ``1/sqrt(n_runs)``).
    probability : float in (0, 1)
        Probability inside the band.
    ax : matplotlib axes, optional
        Drawn on a new figure when None.
    name : str
        "NEES" or "NIS": the axis label.
    label : str, optional
        Legend label of the series (default: ``"mean {name}, {n_runs} runs"``).
    color, marker : str
        The series' colour; a marker draws it as points (for NIS at sparse samples).
    yscale : "auto", "log" or "linear"
        "auto" is logarithmic when the series and the band span more than a factor of ten.
    band_color : str
        The band's colour.

    Returns
    -------
    matplotlib axes
    """
    t = as_times("t", t)
    values = as_float_array("values", values)
    if values.shape != t.shape:
        raise ValueError(f"values: expected one value per time, shape {t.shape}, got shape {values.shape}")
    dof, n_runs = as_count("dof", dof), as_count("n_runs", n_runs)
    probability = as_probability("probability", probability)
    if yscale not in YSCALES:
        raise ValueError(f"yscale: expected one of {YSCALES}, got {yscale!r}")
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7, 3), layout="constrained")
    low, high = chi2_interval(dof, n_runs, probability)
    runs = f"{n_runs} run{'s' if n_runs > 1 else ''}"
    ax.axhspan(low, high, color=band_color, alpha=0.2, lw=0, label=f"{probability:.0%} χ² band ({runs})")
    ax.axhline(dof, color="0.35", ls=":", lw=1, label="expected value")
    style = dict(ls="none", marker=marker, ms=3) if marker else dict(lw=1)
    ax.plot(t, values, color=color, label=label or (name if n_runs == 1 else f"mean {name}, {n_runs} runs"), **style)
    ax.set_xlabel("t [s]")
    ax.set_ylabel(f"mean {name}" if n_runs > 1 else name)
    finite = values[np.isfinite(values) & (values > 0)]
    span = np.r_[finite, low, high]
    if yscale == "log" or (yscale == "auto" and span.max() / span.min() > 10.0):
        ax.set_yscale("log")
        readable_log_axis(ax)
    return ax
