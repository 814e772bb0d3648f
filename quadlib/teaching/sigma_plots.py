"""Pictures of sigma points: where they sit and how much each one weighs (chapter 07).

A sigma point's weight can be negative (a small α pulls the outer points in and the centre must
then subtract), so the picture shows the weight twice: a marker's area grows with ``|w|``, and a
negative weight is drawn hollow. Like every plot in :mod:`quadlib.teaching`, it draws on the ``ax``
it is given (or a new figure) and never on pyplot's current figure.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from quadlib.validation import as_finite_array, as_positive

__all__ = ["plot_sigma_points"]


def plot_sigma_points(points, weights, *, ax=None, annotate: bool | str = True, fmt: str = "+.2f",
                      color: str = "C0", size: float = 90.0, label: str | None = None):
    """Draw 2D sigma points with marker areas proportional to ``|weight|``, hollow where negative.

    Parameters
    ----------
    points : (M, 2) array_like
        The points in the plot's units (rows; for a state in radians convert before calling).
    weights : (M,) array_like
        One weight per point, usually the mean weights :math:`w^m_i` (eq. 7 of Tellex et al. §4).
        The largest ``|weight|`` gets the area ``size``; a weight near zero still gets a twentieth of
        it, so that every point stays visible.
    ax : matplotlib Axes, optional
        Where to draw; a new 4 × 4 in figure when None.
    annotate : bool or "unique"
        Write each weight next to its point, formatted with ``fmt`` (points that coincide get one
        label); ``"unique"`` writes each distinct label once, next to its first point, which keeps
        a symmetric set legible (one label for the centre, one for the outer points).
    fmt : str
        Format specification of the weights (default ``"+.2f"``).
    color : str
        Colour of the markers and labels.
    size : float
        Marker area [pt²] of the heaviest point.
    label : str, optional
        Legend label (given to the positive-weight markers, or the negative ones if all are negative).

    Returns
    -------
    matplotlib Axes
    """
    X = as_finite_array("points", points)
    if X.ndim != 2 or X.shape[1] != 2 or X.shape[0] < 1:
        raise ValueError(f"points: expected shape (M, 2) with M >= 1, got {X.shape}")
    w = as_finite_array("weights", weights)
    if w.shape != (X.shape[0],):
        raise ValueError(f"weights: expected shape ({X.shape[0]},), one per point, got {w.shape}")
    if not (isinstance(annotate, bool) or annotate == "unique"):
        raise TypeError(f"annotate: expected True, False or 'unique', got {annotate!r}")
    if not isinstance(fmt, str):
        raise TypeError(f"fmt: expected a format specification such as '+.2f', got {fmt!r}")
    try:
        format(1.0, fmt)
    except ValueError as err:
        raise ValueError(f"fmt: expected a float format specification such as '+.2f', got {fmt!r}") from err
    if not isinstance(color, str):
        raise TypeError(f"color: expected a matplotlib colour name such as 'C0', got {color!r}")
    size = as_positive("size", size)
    if label is not None and not isinstance(label, str):
        raise TypeError(f"label: expected a str or None, got {label!r}")
    if ax is None:
        _, ax = plt.subplots(figsize=(4, 4), layout="constrained")
    heaviest = np.abs(w).max()
    area = size * np.maximum(np.abs(w) / heaviest if heaviest > 0 else np.ones_like(w), 0.05)
    positive = w >= 0
    if positive.any():
        ax.scatter(X[positive, 0], X[positive, 1], s=area[positive], color=color, edgecolor="k", lw=0.6, zorder=4,
                   label=label)
    if (~positive).any():
        ax.scatter(X[~positive, 0], X[~positive, 1], s=area[~positive], facecolor="none", edgecolor=color, lw=1.6,
                   zorder=4, label=None if positive.any() else label)
    if annotate:
        seen, written = [], set()
        for (px, py), wi in zip(X, w, strict=True):
            text = format(float(wi), fmt)
            if any(np.isclose(px, qx) and np.isclose(py, qy) for qx, qy in seen) or (
                    annotate == "unique" and text in written):
                continue
            seen.append((px, py))
            written.add(text)
            ax.annotate(text, (px, py), textcoords="offset points", xytext=(7, 5), fontsize="small", color=color,
                        zorder=5)
    return ax
