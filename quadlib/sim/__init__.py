"""Simulation shared by every vehicle: model stepping, sensor sampling, trajectories, IMU samples."""

from .faults import imu_faults
from .imu import BodyMotion, imu_samples, specific_force_at_rest
from .simulate import gaussian_factor, sample_sensor, simulate_model, with_dropouts, with_outage, with_outliers
from .trajectories import VerticalRun, min_jerk, piecewise_constant, step_profile, vertical_sine

__all__ = [
    "BodyMotion",
    "VerticalRun",
    "gaussian_factor",
    "imu_faults",
    "imu_samples",
    "min_jerk",
    "piecewise_constant",
    "sample_sensor",
    "simulate_model",
    "specific_force_at_rest",
    "step_profile",
    "vertical_sine",
    "with_dropouts",
    "with_outage",
    "with_outliers",
]
