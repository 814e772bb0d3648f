"""Navigation: the inertial navigation EKF over attitude, velocity, position and the IMU's biases,
and the checks that align a real log's IMU and GPS before it runs."""

from .alignment import accel_noise_equivalent, velocity_change_mismatch
from .ins import (
    InsParams,
    estimate_ins,
    imu_blocks,
    ins_baro_sensor,
    ins_gps_sensor,
    ins_initial_state,
    ins_model,
)

__all__ = ["InsParams", "accel_noise_equivalent", "estimate_ins", "imu_blocks", "ins_baro_sensor", "ins_gps_sensor",
           "ins_initial_state", "ins_model", "velocity_change_mismatch"]
