"""Compile the numba loops the chapters use once, so that no test worker or chapter pays for it.

numba compiles a loop on its first call and caches the machine code next to its source
(``__pycache__``; each filter's engine in ``quadlib/engine/__pycache__/filters``); later processes
load it in a fraction of a second. ``make`` runs this script after installing, so the first test or
chapter finds the cache ready. The work is split into independent tasks run on every core.
"""

import os
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from quadlib import ModelEKF
from quadlib.attitude.bias_model import additive_attitude_bias_model
from quadlib.attitude.complementary import euler_rate_complementary, nonlinear_complementary
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.orientation import (
    OrientationParams,
    estimate_orientation,
    gravity_sensor,
    heading_sensor,
    orientation_run,
)
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.control import altitude_step, fly, fly_path
from quadlib.data import load_px4_log
from quadlib.fixedwing import (
    FixedWingNoise,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.imu import ImuNoise
from quadlib.kernels.linalg import add_refused, scatter_agrees
from quadlib.nav import InsParams, estimate_ins
from quadlib.perception import cast_rays, corridor_map
from quadlib.quad import SensorNoise3D, estimate_quad3d, quad3d_ekf, quad3d_ukf, simulate_run3d, square_course
from quadlib.sim.imu import imu_samples


def _tumble(seconds: float = 3.0):
    motion = random_rotation(seconds, 100.0, np.random.default_rng(0))
    return imu_samples(motion, ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3),
                       np.random.default_rng(1), field_n=earth_field_ned(50.0, np.radians(65.0)))


def orientation() -> None:
    """The orientation MEKF: rest, both low-passes, the forward pass, the backward pass; its kernels
    called from Python."""
    log = _tumble()
    for offline in (False, True):
        estimate_orientation(log, offline=offline)
    short = log.slice(0, 30)
    clipping = float(np.abs(log.gyro).max())
    orientation_run(short, OrientationParams(gyro_range_rad_s=clipping), offline=True, compiled=False)
    ekf = ModelEKF(additive_attitude_bias_model(0.005, 1e-4), np.r_[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                   np.eye(7), 0.01)
    ekf.predict(short.gyro[0])
    for sensor, context in ((heading_sensor(0.1, tilt_aware=True), short.mag[0]), (gravity_sensor(0.5), None)):
        ekf.update_sensor(sensor, sensor.h(ekf.estimate, context) if context is not None else short.accel[0],
                          context=context)
    refused = np.zeros((1, 3))  # a readable reset that waits for agreement: its two kernels from Python
    add_refused(refused, np.zeros(1), np.zeros(1, np.int64), np.ones(1, np.bool_))
    scatter_agrees(refused[0], 1.0, 3.0)


def kesten() -> None:
    """Kesten's filters on the engine, and their kernels called from Python; chapter 10's complementary filters."""
    log = _tumble()
    short = log.slice(0, 30)
    clipping = AttitudeNoise(gyro_range_rad_s=float(np.abs(log.gyro).max()))
    for make in FILTERS.values():
        run_attitude_filter(make(AttitudeNoise()), log)
        run_attitude_filter(make(clipping), short, compiled=False)
    for complementary in (euler_rate_complementary, nonlinear_complementary):
        complementary(0.01, short.gyro, short.accel, 0.5)


def fixedwing() -> None:
    """The fixed-wing filters, both ways."""
    flight, noise = fixedwing_flight(rate_hz=10.0), FixedWingNoise()
    log = fixedwing_samples(flight, noise, np.random.default_rng(2)).slice(0, 100)
    for factory in (salmony_ekf, multiplicative_ekf, error_state_ukf):
        estimate_fixedwing_attitude(log, noise, factory)
        estimate_fixedwing_attitude(log.slice(0, 60), noise, factory, compiled=False)


def quadrotor() -> None:
    """The vehicle and its controllers, chapter 11's filters, the lidar's ray caster."""
    fly(altitude_step(), 0.1, x0=np.r_[np.zeros(6), 1.0, np.zeros(10)])  # x0 is normalised
    fly_path(square_course(leg_s=0.2, turn_s=0.1))
    run = simulate_run3d(square_course(leg_s=1.0, turn_s=1.0), SensorNoise3D(), np.random.default_rng(3), decimate=10)
    for factory in (quad3d_ekf, quad3d_ukf):
        estimate_quad3d(run.t, run.u, run.gps, run.mag, filter_factory=factory)
    cast_rays(np.zeros((1, 2)), np.zeros(1), np.zeros(1), corridor_map())


def navigation() -> None:
    """The inertial navigation filter, forward and smoothed, both ways."""
    px4 = load_px4_log()
    for tilt_aware in (False, True):
        for compiled, rows in ((True, 800), (False, 200)):
            estimate_ins(px4.imu.slice(0, rows), px4.gps, px4.baro, InsParams(heading_tilt_aware=tilt_aware),
                         offline=not tilt_aware, compiled=compiled)


TASKS = (orientation, kesten, fixedwing, quadrotor, navigation)


def _timed(task) -> tuple[str, float]:
    start = time.perf_counter()
    task()
    return task.__name__, time.perf_counter() - start


def main() -> None:
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=min(len(TASKS), os.cpu_count() or 1)) as pool:
        for name, seconds in pool.map(_timed, TASKS):
            print(f"  {name}: {seconds:.1f} s")
    print(f"numba loops compiled or loaded from the cache in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
