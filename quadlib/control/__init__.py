"""Control with the estimator in the loop: Kesten's LQR altitude PID and quaternion attitude PID,
a rigid-body quadrotor with motor lag and limits, and a closed-loop simulator that runs the
controllers on the true state or on the project's filters."""

from .closed_loop import ClosedLoopRun, LoopSensors, PathRun, fly, fly_path
from .controllers import (
    AltitudePid,
    AttitudePid,
    PositionController,
    attitude_error,
    attitude_pid_gains,
    thrust_attitude,
    tilt_angle,
)
from .lqr import AltitudeGains, altitude_model_matrices, altitude_pid_gains, lqr_gain, riccati_gain
from .planar import PlanarRun, hold_distance
from .references import Reference, altitude_step, attitude_wave
from .vehicle import MIXER, QuadrotorParams, hover_state, motor_torques, quadrotor_derivative, quadrotor_step

__all__ = ["MIXER", "AltitudeGains", "AltitudePid", "AttitudePid", "ClosedLoopRun", "LoopSensors", "PathRun",
           "PlanarRun", "PositionController", "QuadrotorParams", "Reference", "altitude_model_matrices",
           "altitude_pid_gains", "altitude_step", "attitude_error", "attitude_pid_gains", "attitude_wave", "fly",
           "fly_path", "hold_distance", "hover_state", "lqr_gain", "motor_torques", "quadrotor_derivative",
           "quadrotor_step", "riccati_gain", "thrust_attitude", "tilt_angle"]
