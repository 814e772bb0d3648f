"""Navigation: the inertial navigation EKF over attitude, velocity, position and the IMU's biases,
the checks that align a real log's IMU and GPS before it runs, and scan matching as its measurement
where there is no GPS."""

from .aiding import ins_pose_sensor, pose_measurements
from .alignment import accel_noise_equivalent, velocity_change_mismatch
from .denied import AIDS, DeniedFlight, match_poses, navigate, sim_params, simulate_denied_flight
from .ins import (
    InsParams,
    estimate_ins,
    imu_blocks,
    ins_baro_sensor,
    ins_gps_sensor,
    ins_initial_state,
    ins_model,
)

__all__ = ["AIDS", "DeniedFlight", "InsParams", "accel_noise_equivalent", "estimate_ins", "imu_blocks",
           "ins_baro_sensor", "ins_gps_sensor", "ins_initial_state", "ins_model", "ins_pose_sensor", "match_poses",
           "navigate", "pose_measurements", "sim_params", "simulate_denied_flight", "velocity_change_mismatch"]
