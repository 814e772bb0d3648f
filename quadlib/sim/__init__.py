"""Simulation shared by every vehicle: model stepping, sensor sampling, trajectories, IMU samples."""

from .simulate import sample_sensor, simulate_model, with_dropouts, with_outliers
from .trajectories import piecewise_constant, step_profile

__all__ = [
    "piecewise_constant",
    "sample_sensor",
    "simulate_model",
    "step_profile",
    "with_dropouts",
    "with_outliers",
]
