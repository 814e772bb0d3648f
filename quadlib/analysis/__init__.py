"""Measuring filters: error metrics, consistency (NEES/NIS) and Monte Carlo runs."""

from .metrics import (
    angle_error,
    angle_rmse,
    attitude_error,
    attitude_rmse,
    broad_errors,
    chi2_interval,
    fraction_inside,
    nees,
    nis,
    rmse,
    settling_time,
)
from .montecarlo import Moments, MonteCarloRuns, importance_posterior, propagate_samples, run_monte_carlo

__all__ = [
    "Moments",
    "MonteCarloRuns",
    "angle_error",
    "angle_rmse",
    "attitude_error",
    "attitude_rmse",
    "broad_errors",
    "chi2_interval",
    "fraction_inside",
    "importance_posterior",
    "nees",
    "nis",
    "propagate_samples",
    "rmse",
    "run_monte_carlo",
    "settling_time",
]
