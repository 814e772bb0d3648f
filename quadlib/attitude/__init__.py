"""Attitude and altitude estimation for a quadrotor: complementary filters, Kesten's filters, the altitude filter."""

from .altitude import (
    SEA_LEVEL_HPA,
    altitude_from_pressure,
    altitude_model,
    baro_altitude_sensor,
    pressure_from_altitude,
    vertical_specific_force,
)
from .complementary import blend_weight, euler_rate_complementary, linear_complementary, nonlinear_complementary
from .kesten import FILTERS, QF, QKF, TOVKF, TQF, TQKF, AttitudeNoise, run_attitude_filter, vector_jacobian
from .tumble import attitude_samples, random_rotation

__all__ = [
    "AttitudeNoise",
    "FILTERS",
    "QF",
    "QKF",
    "SEA_LEVEL_HPA",
    "TOVKF",
    "TQF",
    "TQKF",
    "altitude_from_pressure",
    "altitude_model",
    "attitude_samples",
    "baro_altitude_sensor",
    "blend_weight",
    "euler_rate_complementary",
    "linear_complementary",
    "nonlinear_complementary",
    "pressure_from_altitude",
    "random_rotation",
    "run_attitude_filter",
    "vector_jacobian",
    "vertical_specific_force",
]
