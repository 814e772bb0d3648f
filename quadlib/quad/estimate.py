"""The 7-state 3D quadrotor EKF of chapter 11 in one call, with the chapter's tuning as documented defaults."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from quadlib.filters import ModelEKF, ModelUKF
from quadlib.model import Model, Sensor
from quadlib.quad.quad3d import quad3d_gps_sensor, quad3d_mag_sensor, quad3d_model, quad3d_ukf_options
from quadlib.replay import FilterRun, run_filter
from quadlib.samples import Measurements, Samples
from quadlib.validation import as_bool, as_instance, as_times, as_vector, check_fields

__all__ = ["LAYOUT", "Quad3DParams", "estimate_quad3d", "quad3d_ekf", "quad3d_ukf"]

LAYOUT = {"p": slice(0, 3), "v": slice(3, 6), "yaw": 6}  # the parts of x, for FilterRun.layout


@dataclass(frozen=True)
class Quad3DParams:
    """Chapter 11's tuning of the 7-state EKF ``[x, y, z, ẋ, ẏ, ż, ψ]`` for a 50 Hz filter step.

    Parameters
    ----------
    accel_sigma_m_s2 : (3,) tuple
        Acceleration error per step, per NED axis [m/s²]. Horizontal 2 m/s²: it must cover the
        complementary filter's tilt error, which leaks gravity into the horizontal acceleration
        for seconds (chapter 11 sweeps 0.3, 1, 2, 4 m/s²: the mean NEES falls steeply up to 2 m/s² and
        then levels off).
        Vertical 1.5/√10 ≈ 0.47 m/s²: the accelerometer's σ averaged over 10 IMU samples.
    yaw_rate_sigma_rad_s : float
        Yaw-rate input error [rad/s]: the gyro's 0.5 rad/s averaged over 10 samples, ≈ 0.16.
    gps_pos_sigma_m, gps_vel_sigma_m_s : (3,) tuples
        GPS noise per NED axis [m], [m/s] (the course simulator's receiver).
    mag_yaw_sigma_rad : float
        Magnetometer heading noise [rad].
    initial_sigma : (7,) tuple
        σ of the initial state [m, m, m, m/s, m/s, m/s, rad].
    gate_probability : float in (0, 1) or None
        χ² gate on each update's NIS in :func:`estimate_quad3d` (see :func:`quadlib.run_filter`);
        None (default): no gate.
    """

    accel_sigma_m_s2: tuple = (2.0, 2.0, 1.5 / float(np.sqrt(10.0)))
    yaw_rate_sigma_rad_s: float = 0.5 / float(np.sqrt(10.0))
    gps_pos_sigma_m: tuple = (0.7, 0.7, 2.0)
    gps_vel_sigma_m_s: tuple = (0.1, 0.1, 0.3)
    mag_yaw_sigma_rad: float = 0.1
    initial_sigma: tuple = (1.0, 1.0, 2.0, 0.1, 0.1, 0.3, 0.1)
    gate_probability: float | None = None

    def __post_init__(self):
        check_fields(self, {"accel_sigma_m_s2": "positive or 3", "yaw_rate_sigma_rad_s": "positive",
                            "gps_pos_sigma_m": "positive or 3", "gps_vel_sigma_m_s": "positive or 3",
                            "mag_yaw_sigma_rad": "positive", "initial_sigma": "positives",
                            "gate_probability": "optional probability"})

    def model(self) -> Model:
        """The transition model (eq. 49, NED gravity) with this process noise."""
        return quad3d_model(self.accel_sigma_m_s2, self.yaw_rate_sigma_rad_s)

    def sensors(self) -> tuple[Sensor, Sensor]:
        """GPS position and velocity (eqs. 53–55) and magnetometer heading (eqs. 56–58)."""
        gps = quad3d_gps_sensor(self.gps_pos_sigma_m, self.gps_vel_sigma_m_s)
        return gps, quad3d_mag_sensor(self.mag_yaw_sigma_rad)

    @property
    def P0(self) -> np.ndarray:
        """Initial covariance ``diag(initial_sigma)²``."""
        return np.diag(np.asarray(self.initial_sigma, dtype=float) ** 2)


def quad3d_ekf(x0, dt: float, params: Quad3DParams = Quad3DParams()) -> ModelEKF:
    """The 7-state EKF at ``x0`` with step ``dt`` [s]."""
    params = as_instance("params", params, Quad3DParams)
    return ModelEKF(params.model(), x0, params.P0, dt)


def quad3d_ukf(x0, dt: float, params: Quad3DParams = Quad3DParams()) -> ModelUKF:
    """The same model in a UKF (default sigma points, α = 0.5; the yaw averaged on the circle,
    :func:`~quadlib.quad.quad3d.quad3d_ukf_options`)."""
    params = as_instance("params", params, Quad3DParams)
    return ModelUKF(params.model(), x0, params.P0, dt, **quad3d_ukf_options())


def estimate_quad3d(t, u, gps: Samples, mag: Samples, x0=None, params: Quad3DParams = Quad3DParams(),
                    filter_factory=quad3d_ekf, compiled: bool = True) -> FilterRun:
    """Position, velocity and yaw of a quadrotor from its IMU inputs, GPS and magnetometer, in one call.

    Parameters
    ----------
    t : (N,) array_like
        The filter's times [s] (uniform step).
    u : (N, 6) array_like
        Inputs: specific force (FRD) [m/s²], yaw rate [rad/s], roll and pitch [rad]
        (:func:`quadlib.quad.imu_inputs` builds them from an IMU log and an attitude filter).
    gps : Samples
        GPS ``[x, y, z, ẋ, ẏ, ż]`` (NED, m and m/s); NaN rows are missing fixes.
    mag : Samples
        Magnetometer heading [rad].
    x0 : (7,) array_like, optional
        Initial state; by default the first GPS fix (position and velocity) and the first heading.
    params : Quad3DParams
        The model's and sensors' noise, the initial σ and the gate.
    filter_factory : callable
        :func:`quad3d_ekf` (default) or :func:`quad3d_ukf`.
    compiled : bool
        Run the same steps on the compiled engine (:mod:`quadlib.engine`; equal to the readable
        loop to 1e-10, tested; ``run.engine`` says which ran). False runs the readable filter
        driven by :func:`~quadlib.run_filter`.

    Returns
    -------
    FilterRun
        ``x`` (N, 7) and ``sigma`` (N, 7); the parts of ``x`` by name (``LAYOUT``): ``run.p`` (N, 3),
        ``run.v`` (N, 3), ``run.yaw`` (N,).
    """
    for name, s in (("gps", gps), ("mag", mag)):
        if not isinstance(s, Samples):
            raise TypeError(f"{name}: expected Samples, got {type(s).__name__}")
    if x0 is None:
        if not (gps.t.size and mag.t.size):
            raise ValueError("gps, mag: expected at least one sample of each to start from, got none")
        x0 = np.concatenate([gps.z[0], mag.z[0]])
    x0 = as_vector("x0", x0, 7)
    t = as_times("t", t)
    params = as_instance("params", params, Quad3DParams)
    if not callable(filter_factory):
        raise TypeError(f"filter_factory: expected a callable such as quad3d_ekf, got {filter_factory!r}")
    compiled = as_bool("compiled", compiled)
    gps_sensor, mag_sensor = params.sensors()
    filt = filter_factory(x0, float(t[1] - t[0]), params)
    measurements = [Measurements(gps_sensor, gps.t, gps.z), Measurements(mag_sensor, mag.t, mag.z)]
    run = run_filter(filt, t, u, measurements, gate_probability=params.gate_probability,
                     engine="auto" if compiled else "readable")
    return replace(run, layout=dict(LAYOUT))

