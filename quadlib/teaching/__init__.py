"""Helpers that exist only for teaching: averaging, histograms, plots, animations, and the graded exercises."""

from .animation import animate_quad2d, animation_html, quad2d_geometry
from .averaging import batch_mean, exponential_average, half_average, recursive_mean
from .display import show_source
from .grading import Exercise, Grade, Mutation, exercises, grade_notebook, mutation_run, student_edition
from .histogram import belief_mean_std, gaussian_belief, gaussian_kernel, gaussian_likelihood, uniform_grid
from .plotting import plot_consistency, plot_estimate, plot_innovations

__all__ = [
    "Exercise",
    "Grade",
    "Mutation",
    "animate_quad2d",
    "animation_html",
    "batch_mean",
    "belief_mean_std",
    "exercises",
    "exponential_average",
    "gaussian_belief",
    "gaussian_kernel",
    "gaussian_likelihood",
    "grade_notebook",
    "half_average",
    "mutation_run",
    "plot_consistency",
    "plot_estimate",
    "plot_innovations",
    "quad2d_geometry",
    "recursive_mean",
    "show_source",
    "student_edition",
    "uniform_grid",
]
