"""Salmony's fixed-wing attitude problem: model, simulated flight and estimators."""

from .estimate import (
    FixedWingParams,
    complementary_attitude,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_measurements,
    initial_state,
    multiplicative_ekf,
    salmony_ekf,
)
from .model import (
    FixedWingNoise,
    accel_jacobian,
    accel_model,
    airspeed_from_pressure,
    fixedwing_A,
    fixedwing_accel_sensor,
    fixedwing_f,
    fixedwing_mag_sensor,
    fixedwing_model,
    lowpass2,
    mag_jacobian,
    mag_model,
)
from .sim import FixedWingFlight, aileron_roll, fixedwing_flight, fixedwing_samples

__all__ = [
    "FixedWingFlight",
    "FixedWingNoise",
    "FixedWingParams",
    "accel_jacobian",
    "accel_model",
    "aileron_roll",
    "airspeed_from_pressure",
    "complementary_attitude",
    "error_state_ukf",
    "estimate_fixedwing_attitude",
    "fixedwing_A",
    "fixedwing_accel_sensor",
    "fixedwing_f",
    "fixedwing_flight",
    "fixedwing_mag_sensor",
    "fixedwing_measurements",
    "fixedwing_model",
    "fixedwing_samples",
    "initial_state",
    "lowpass2",
    "mag_jacobian",
    "mag_model",
    "multiplicative_ekf",
    "salmony_ekf",
]
