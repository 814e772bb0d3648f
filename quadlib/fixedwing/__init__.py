"""Salmony's fixed-wing attitude problem: model, simulated flight and estimators."""

from .ekf import fixedwing_accel_sensor, fixedwing_mag_sensor, fixedwing_model, initial_state, run_fixedwing_ekf
from .model import (
    accel_jacobian,
    accel_model,
    airspeed_from_pressure,
    fixedwing_A,
    fixedwing_f,
    lowpass2,
    mag_jacobian,
    mag_model,
    quaternion_rate_matrix,
)
from .run import ESTIMATORS, run_estimator
from .sim import FixedWingFlight, FixedWingNoise, FixedWingSamples, fixedwing_flight, fixedwing_samples
from .ukf import ErrorStateUKF

__all__ = [
    "ESTIMATORS",
    "ErrorStateUKF",
    "FixedWingFlight",
    "FixedWingNoise",
    "FixedWingSamples",
    "accel_jacobian",
    "accel_model",
    "airspeed_from_pressure",
    "fixedwing_A",
    "fixedwing_accel_sensor",
    "fixedwing_f",
    "fixedwing_flight",
    "fixedwing_mag_sensor",
    "fixedwing_model",
    "fixedwing_samples",
    "initial_state",
    "lowpass2",
    "mag_jacobian",
    "mag_model",
    "quaternion_rate_matrix",
    "run_estimator",
    "run_fixedwing_ekf",
]
