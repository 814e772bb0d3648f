"""One simulated 3D flight, ready for the filters of chapter 11: an experiment harness.

It joins the simulator (:mod:`quadlib.quad.flight`, :func:`quadlib.sim.imu_samples`) to the
estimator's inputs (a complementary filter for roll and pitch), so it depends on both; only
chapters, tests and benchmarks import it, never a simulator or an estimator.

:func:`simulate_run3d` draws the IMU, GPS, magnetometer and barometer samples of a
:class:`~quadlib.quad.flight.Flight3D`, runs a complementary filter for roll and pitch at the IMU
rate, and builds the 7-state model's inputs at the filter rate (IMU samples averaged in blocks
of ``decimate``). :func:`run3d_measurements` wraps the samples for :func:`quadlib.run_filter`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.attitude.complementary import euler_rate_complementary
from quadlib.imu import ImuLog
from quadlib.model import Sensor
from quadlib.quad.flight import (
    Flight3D,
    SensorNoise3D,
    baro_samples,
    gps_samples,
    mag_field_samples,
    mag_yaw_samples,
)
from quadlib.quad.quad3d import imu_inputs
from quadlib.samples import Measurements, Samples
from quadlib.sim.imu import imu_samples
from quadlib.validation import as_count, as_instance

__all__ = ["Run3D", "imu_with_magnetometer", "run3d_measurements", "simulate_run3d"]


@dataclass(frozen=True)
class Run3D:
    """A simulated flight on the filter's time grid ``t`` (``M`` steps).

    Attributes
    ----------
    t : (M,) filter times [s]
    u : (M, 6) model inputs (specific force, yaw rate, roll, pitch)
    truth : (M, 7) true ``[x, y, z, ẋ, ẏ, ż, ψ]``
    true_roll_pitch, roll_pitch : (M, 2) true and complementary-filter roll and pitch [rad]
    gps, mag, baro : Samples within ``[t[0], t[-1]]``
    imu : ImuLog
        The IMU samples at the flight's rate (gyro, accelerometer; no magnetometer).
    """

    t: np.ndarray
    u: np.ndarray
    truth: np.ndarray
    true_roll_pitch: np.ndarray
    roll_pitch: np.ndarray
    gps: Samples
    mag: Samples
    baro: Samples
    imu: ImuLog


def simulate_run3d(flight: Flight3D, noise: SensorNoise3D, rng, decimate: int = 10, tau: float = 5.0,
                   true_attitude: bool = False) -> Run3D:
    """Sample every sensor of ``flight`` once and prepare the filter inputs.

    ``tau`` is the complementary filter's time constant [s]; ``true_attitude=True`` feeds the
    model the true roll and pitch instead (an oracle, to separate the attitude's share of the error).
    """
    decimate = as_count("decimate", decimate)
    imu = imu_samples(flight, noise, rng)
    gps, mag = gps_samples(flight, noise, rng), mag_yaw_samples(flight, noise, rng)
    baro = baro_samples(flight, noise, rng)
    cf = euler_rate_complementary(flight.dt, imu.gyro, imu.accel, tau)
    attitude = flight.euler[:, :2] if true_attitude else cf
    u = imu_inputs(flight.dt, imu.accel, imu.gyro, attitude, decimate=decimate)
    k = np.arange(u.shape[0]) * decimate
    t = flight.t[k]
    truth = np.column_stack([flight.pos[k], flight.vel[k], flight.euler[k, 2]])
    return Run3D(t=t, u=u, truth=truth, true_roll_pitch=flight.euler[k, :2], roll_pitch=cf[k],
                 gps=gps.between(t[0], t[-1]), mag=mag.between(t[0], t[-1]), baro=baro.between(t[0], t[-1]),
                 imu=imu)


def run3d_measurements(run: Run3D, gps_sensor, mag_sensor, baro_sensor=None) -> list[Measurements]:
    """The run's samples as :class:`quadlib.Measurements` for the given sensor models."""
    run = as_instance("run", run, Run3D)
    for name, sensor in (("gps_sensor", gps_sensor), ("mag_sensor", mag_sensor), ("baro_sensor", baro_sensor)):
        if sensor is not None or name != "baro_sensor":
            as_instance(name, sensor, Sensor)
    out = [Measurements(gps_sensor, run.gps.t, run.gps.z), Measurements(mag_sensor, run.mag.t, run.mag.z)]
    if baro_sensor is not None:
        out.append(Measurements(baro_sensor, run.baro.t, run.baro.z))
    return out


def imu_with_magnetometer(run: Run3D, flight: Flight3D, noise: SensorNoise3D, rng) -> ImuLog:
    """The run's IMU log with a three-axis magnetometer (:func:`~quadlib.quad.flight.mag_field_samples`,
    drawn now from ``rng``) in the rows of its samples, NaN in the others: what the inertial
    navigation filter reads where the 7-state EKF reads a heading."""
    run, flight = as_instance("run", run, Run3D), as_instance("flight", flight, Flight3D)
    field = mag_field_samples(flight, noise, rng)
    mag = np.full((flight.t.size, 3), np.nan)
    mag[np.searchsorted(flight.t, field.t)] = field.z
    return ImuLog(run.imu.t, run.imu.gyro, run.imu.accel, mag)
