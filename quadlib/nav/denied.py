"""Flying without GPS: the inertial navigation filter aided by scan matching against a map.

:func:`simulate_denied_flight` flies a :class:`~quadlib.quad.Flight3D` through a map of walls and
records what the quadrotor would: its IMU (:class:`~quadlib.quad.SensorNoise3D`), barometer, GPS
(for comparison only — indoors there is none) and a horizontal lidar. :func:`navigate` then runs
one filter — the INS of :mod:`quadlib.nav.ins`, on :func:`quadlib.run_filter` — with a choice of
aids: nothing but the barometer (IMU dead reckoning), GPS, or the lidar's poses from
:func:`~quadlib.perception.track_scans` (loosely coupled, :mod:`quadlib.nav.aiding`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from quadlib.filters import ModelEKF
from quadlib.imu import ImuLog
from quadlib.nav.aiding import pose_measurements
from quadlib.nav.ins import LAYOUT, InsParams, imu_blocks, ins_baro_sensor, ins_gps_sensor
from quadlib.perception.lidar import lidar_scan
from quadlib.perception.map_matching import MapMatch, track_scans, wall_points
from quadlib.quad.flight import Flight3D, SensorNoise3D, baro_samples, gps_samples
from quadlib.replay import FilterRun, run_filter
from quadlib.samples import Measurements, Samples
from quadlib.sim.imu import imu_samples
from quadlib.validation import as_finite_array, as_instance, as_positive, as_rng

__all__ = ["AIDS", "DeniedFlight", "match_poses", "navigate", "sim_params", "simulate_denied_flight"]

AIDS = ("none", "gps", "scans")


@dataclass(frozen=True)
class DeniedFlight:
    """A simulated flight through a map: the true ``flight``, the ``imu`` log, ``baro`` and ``gps``
    samples, the map's ``walls`` (S, 2, 2) in the north–east plane, and the lidar's scans: their
    times ``scan_t`` (K,), returns ``scans`` (K arrays of (n, 2) points, sensor frame) and the
    poses ``matches`` (K,) that scan-to-map tracking found (``None``: too few returns); the sensors'
    ``noise``."""

    flight: Flight3D
    imu: ImuLog
    baro: Samples
    gps: Samples
    walls: np.ndarray
    scan_t: np.ndarray
    scans: list
    matches: list
    noise: SensorNoise3D


def simulate_denied_flight(flight: Flight3D, walls, rng, *, noise: SensorNoise3D | None = None,
                           lidar_rate_hz: float = 10.0, beams: int = 360, max_range_m: float = 12.0,
                           range_sigma_m: float = 0.02, dropout: float = 0.05) -> DeniedFlight:
    """Sample the sensors of ``flight`` in the map ``walls`` and track the scans from the true
    start (module documentation); ``noise`` by default :class:`~quadlib.quad.SensorNoise3D`'s. The
    lidar's settings are :func:`~quadlib.perception.lidar_scan`'s."""
    flight = as_instance("flight", flight, Flight3D)
    noise = SensorNoise3D() if noise is None else as_instance("noise", noise, SensorNoise3D)
    walls = as_finite_array("walls", walls)
    if walls.ndim != 3 or walls.shape[1:] != (2, 2):
        raise ValueError(f"walls: expected wall segments of shape (S, 2, 2), got {walls.shape}")
    rng = as_rng(rng)
    step = int(round(1.0 / (as_positive("lidar_rate_hz", lidar_rate_hz) * flight.dt)))
    if step < 1:
        raise ValueError(f"lidar_rate_hz: expected at most the flight's rate {1 / flight.dt:g} Hz, got {lidar_rate_hz}")
    k = np.arange(0, flight.t.size, step)
    imu, baro, gps = imu_samples(flight, noise, rng), baro_samples(flight, noise, rng), gps_samples(flight, noise, rng)
    poses = np.column_stack([flight.pos[k, :2], flight.euler[k, 2]])
    scans = [lidar_scan(pose, walls, rng, beams=beams, max_range_m=max_range_m, range_sigma_m=range_sigma_m,
                        dropout=dropout).points for pose in poses]
    points, normals = wall_points(walls)
    matches = track_scans(scans, points, normals, poses[0])
    return DeniedFlight(flight=flight, imu=imu, baro=baro, gps=gps, walls=walls,
                        scan_t=flight.t[k], scans=scans, matches=matches, noise=noise)


def navigate(run: DeniedFlight, aid: str, params: InsParams | None = None, *, decimate: int = 10) -> FilterRun:
    """The INS over ``run`` from its true start (σ 0.1 m, 0.05 m/s, and ``params``' attitude and bias
    σ), aided by the barometer and ``aid``: ``"none"`` (dead reckoning), ``"gps"`` or ``"scans"``,
    every update gated at ``params.gate_probability``. By default ``params`` are the simulator's
    noise (:func:`sim_params`). The run's state parts are :func:`~quadlib.nav.estimate_ins`'s."""
    run = as_instance("run", run, DeniedFlight)
    if aid not in AIDS:
        raise ValueError(f"aid: expected one of {AIDS}, got {aid!r}")
    params = sim_params(run.noise) if params is None else as_instance("params", params, InsParams)
    t, u = imu_blocks(run.imu, decimate)
    f = run.flight
    x0 = np.concatenate([f.q_nb[0], f.vel[0], f.pos[0], np.zeros(6)])
    ekf = ModelEKF(params.model(decimate), x0, params.initial_covariance([0.1] * 3, [0.05] * 3), float(t[1] - t[0]))
    aids = [Measurements(ins_baro_sensor(params.baro_sigma_m), run.baro.t, run.baro.z)]
    if aid == "gps":
        aids.append(Measurements(ins_gps_sensor(params.gps_pos_sigma_m, params.gps_vel_sigma_m_s), run.gps.t,
                                 run.gps.z))
    elif aid == "scans":
        aids.append(pose_measurements(run.scan_t, run.matches))
    run = run_filter(ekf, t, u, [m.between(t[0], t[-1]) for m in aids], gate_probability=params.gate_probability)
    return replace(run, layout=dict(LAYOUT))


def sim_params(noise: SensorNoise3D) -> InsParams:
    """The INS's parameters that match the simulator's ``noise`` (its IMU, GPS and barometer σ)."""
    noise = as_instance("noise", noise, SensorNoise3D)
    return InsParams(gyro_sigma_rad_s=noise.gyro_sigma_rad_s, accel_sigma_m_s2=noise.accel_sigma_m_s2,
                     gps_pos_sigma_m=noise.gps_pos_sigma_m, gps_vel_sigma_m_s=noise.gps_vel_sigma_m_s,
                     baro_sigma_m=noise.baro_sigma_m)


def match_poses(matches) -> np.ndarray:
    """The poses (K, 3) of a list of :class:`~quadlib.perception.MapMatch` (NaN rows for ``None``)."""
    out = []
    for j, m in enumerate(matches):
        if m is not None and not isinstance(m, MapMatch):
            raise TypeError(f"matches[{j}]: expected a MapMatch or None, got {type(m).__name__}")
        out.append(np.full(3, np.nan) if m is None else m.pose)
    return np.array(out).reshape(-1, 3)
