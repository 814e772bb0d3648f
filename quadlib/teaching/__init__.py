"""Helpers that exist only for teaching: averaging, histograms, the one-number Kalman filter's flight and
slider, plots, animations, progress bars, and the graded exercises."""

from quadlib.progress import progress

from .animation import animate_quad2d, animation_html, quad2d_geometry
from .averaging import batch_mean, exponential_average, half_average, recursive_mean
from .bands import plot_chi2_band, readable_log_axis
from .cart import cart_model, cart_position_sensor, cart_speed_sensor
from .cart_tuning import CartTuningTrial, cart_push_input, cart_tuning_trial
from .display import rounding, show_source, span
from .grading import Exercise, Mutation, exercises, mutation_run, try_answers
from .histogram import belief_mean_std, gaussian_belief, gaussian_kernel, gaussian_likelihood, uniform_grid
from .one_number import ClimbFlight, OneNumberTrial, climb_flight, one_number_trial
from .plotting import covariance_ellipse, plot_consistency, plot_covariance_ellipse, plot_estimate, plot_innovations
from .sigma_plots import plot_sigma_points
from .tuning import (
                     ComplementaryTrial,
                     GateTrial,
                     KfTuningTrial,
                     complementary_trial,
                     gate_trial,
                     kf_tuning_trial,
                     plot_trial,
                     show_trial,
                     tuning_sliders,
)

__all__ = [
    "CartTuningTrial",
    "ClimbFlight",
    "ComplementaryTrial",
    "GateTrial",
    "KfTuningTrial",
    "OneNumberTrial",
    "Exercise",
    "Mutation",
    "animate_quad2d",
    "animation_html",
    "batch_mean",
    "cart_model",
    "cart_position_sensor",
    "cart_push_input",
    "cart_speed_sensor",
    "cart_tuning_trial",
    "climb_flight",
    "complementary_trial",
    "covariance_ellipse",
    "gate_trial",
    "kf_tuning_trial",
    "one_number_trial",
    "plot_trial",
    "show_trial",
    "tuning_sliders",
    "belief_mean_std",
    "exercises",
    "exponential_average",
    "gaussian_belief",
    "gaussian_kernel",
    "gaussian_likelihood",
    "half_average",
    "mutation_run",
    "try_answers",
    "plot_chi2_band",
    "plot_consistency",
    "plot_covariance_ellipse",
    "plot_estimate",
    "plot_innovations",
    "plot_sigma_points",
    "progress",
    "quad2d_geometry",
    "readable_log_axis",
    "recursive_mean",
    "rounding",
    "show_source",
    "span",
    "uniform_grid",
]
