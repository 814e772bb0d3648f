"""Helpers that exist only for a chapter's explanation: averaging, histograms, plots, animations."""

from .animation import animate_quad2d, animation_html, quad2d_geometry
from .averaging import batch_mean, exponential_average, half_average, recursive_mean
from .display import show_source
from .histogram import belief_mean_std, gaussian_belief, gaussian_kernel, gaussian_likelihood, uniform_grid
from .plotting import plot_consistency, plot_estimate, plot_innovations

__all__ = [
    "animate_quad2d",
    "animation_html",
    "batch_mean",
    "belief_mean_std",
    "exponential_average",
    "gaussian_belief",
    "gaussian_kernel",
    "gaussian_likelihood",
    "half_average",
    "plot_consistency",
    "plot_estimate",
    "plot_innovations",
    "quad2d_geometry",
    "recursive_mean",
    "show_source",
    "uniform_grid",
]
