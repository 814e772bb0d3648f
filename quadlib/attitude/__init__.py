"""Attitude and altitude estimation for a quadrotor: complementary filters, Kesten's filters, the altitude filter."""

from quadlib.sensors import GYRO_NAMES, gravity_sensor, heading_sensor, zero_rate_sensor

from .altitude import (
    SEA_LEVEL_HPA,
    altitude_from_pressure,
    altitude_model,
    baro_altitude_sensor,
    pressure_from_altitude,
    vertical_specific_force,
)
from .bias_model import (
    STATE_NAMES,
    additive_attitude_bias_model,
    as_attitude_state,
    attitude_bias_model,
    gyro_step,
    gyro_step_jacobian,
    normalize_attitude,
    normalize_attitude_jacobian,
    quaternion_rate_matrix,
)
from .checks import SensorChecks, plausible_accel, plausible_mag, undisturbed_field
from .complementary import blend_weight, euler_rate_complementary, linear_complementary, nonlinear_complementary
from .kesten import FILTERS, AttitudeNoise, AttitudeRun, KestenFilter, qf, qkf, run_attitude_filter, tovkf, tqf, tqkf
from .lowpass import inertial_lowpass, rest_mask
from .orientation import OrientationParams, estimate_orientation, orientation_run
from .tumble import random_rotation, with_spin

__all__ = [
    "AttitudeNoise",
    "AttitudeRun",
    "FILTERS",
    "GYRO_NAMES",
    "KestenFilter",
    "OrientationParams",
    "SEA_LEVEL_HPA",
    "STATE_NAMES",
    "SensorChecks",
    "altitude_from_pressure",
    "altitude_model",
    "as_attitude_state",
    "additive_attitude_bias_model",
    "attitude_bias_model",
    "baro_altitude_sensor",
    "blend_weight",
    "estimate_orientation",
    "euler_rate_complementary",
    "gravity_sensor",
    "gyro_step",
    "gyro_step_jacobian",
    "heading_sensor",
    "inertial_lowpass",
    "linear_complementary",
    "nonlinear_complementary",
    "orientation_run",
    "normalize_attitude",
    "normalize_attitude_jacobian",
    "plausible_accel",
    "plausible_mag",
    "undisturbed_field",
    "pressure_from_altitude",
    "qf",
    "qkf",
    "quaternion_rate_matrix",
    "random_rotation",
    "rest_mask",
    "run_attitude_filter",
    "tovkf",
    "tqf",
    "tqkf",
    "vertical_specific_force",
    "with_spin",
    "zero_rate_sensor",
]
