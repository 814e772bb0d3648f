"""The quadrotor models of Tellex et al. §5–7, their flights and the blog's pipeline."""

from .estimate import Quad3DParams, estimate_quad3d, quad3d_ekf, quad3d_ukf
from .flight import (
    Flight3D,
    SensorNoise3D,
    baro_samples,
    figure_eight,
    flight_from_path,
    gps_samples,
    mag_field_samples,
    mag_yaw_samples,
    square_course,
    straight_course,
)
from .height import height_model, range_sensor
from .pipeline import simple_pipeline
from .quad1d import climb_input, quad1d_model, quad1d_range_sensor
from .quad2d import quad2d_model, quad2d_range_sensor
from .quad3d import (
    imu_inputs,
    quad3d_baro_sensor,
    quad3d_gps_sensor,
    quad3d_mag_sensor,
    quad3d_model,
    quad3d_ukf_options,
)
from .rangefinder import tilted_range_sensor
from .scenario import Run3D, imu_with_magnetometer, run3d_measurements, simulate_run3d

__all__ = [
    "Flight3D",
    "Quad3DParams",
    "Run3D",
    "SensorNoise3D",
    "baro_samples",
    "estimate_quad3d",
    "figure_eight",
    "flight_from_path",
    "gps_samples",
    "height_model",
    "imu_with_magnetometer",
    "imu_inputs",
    "mag_field_samples",
    "mag_yaw_samples",
    "climb_input",
    "quad1d_model",
    "quad1d_range_sensor",
    "quad2d_model",
    "quad2d_range_sensor",
    "quad3d_baro_sensor",
    "quad3d_ekf",
    "quad3d_ukf",
    "quad3d_gps_sensor",
    "quad3d_mag_sensor",
    "quad3d_model",
    "quad3d_ukf_options",
    "range_sensor",
    "run3d_measurements",
    "simple_pipeline",
    "simulate_run3d",
    "square_course",
    "straight_course",
    "tilted_range_sensor",
]
