"""Compile quadlib's numba loops once, so that no test worker or chapter pays for it.

numba compiles a loop on its first call and caches the machine code next to its source
(``__pycache__``); later processes load it in a fraction of a second. ``make`` runs this script
after installing, so the first test or chapter finds the cache ready.
"""

import time

import numpy as np

from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.orientation import estimate_orientation
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.control import altitude_step, fly
from quadlib.data import load_px4_log
from quadlib.fixedwing import (
    FixedWingNoise,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    salmony_ekf,
)
from quadlib.imu import ImuNoise
from quadlib.nav import InsParams, estimate_ins
from quadlib.perception import cast_rays, corridor_map
from quadlib.quad import SensorNoise3D, estimate_quad3d, quad3d_ekf, quad3d_ukf, simulate_run3d, square_course
from quadlib.sim.imu import imu_samples


def main() -> None:
    start = time.perf_counter()
    motion = random_rotation(3.0, 100.0, np.random.default_rng(0))
    log = imu_samples(motion, ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3),
                      np.random.default_rng(1), field_n=earth_field_ned(50.0, np.radians(65.0)))
    for offline in (False, True):  # every loop: rest, both low-passes, the forward pass, the backward pass
        estimate_orientation(log, offline=offline)
    for make in FILTERS.values():  # Kesten's filters
        run_attitude_filter(make(AttitudeNoise()), log)
    cast_rays(np.zeros((1, 2)), np.zeros(1), np.zeros(1), corridor_map())  # the lidar's ray caster
    flight, noise = fixedwing_flight(rate_hz=10.0), FixedWingNoise()
    fw_log = fixedwing_samples(flight, noise, np.random.default_rng(2)).slice(0, 100)
    for factory in (salmony_ekf, error_state_ukf):  # the fixed-wing filters
        estimate_fixedwing_attitude(fw_log, noise, factory)
    fly(altitude_step(), 0.1)  # the closed loop's vehicle
    run = simulate_run3d(square_course(leg_s=1.0, turn_s=1.0), SensorNoise3D(), np.random.default_rng(3), decimate=10)
    for factory in (quad3d_ekf, quad3d_ukf):  # chapter 11's filters
        estimate_quad3d(run.t, run.u, run.gps, run.mag, filter_factory=factory)
    px4 = load_px4_log()
    for tilt_aware in (False, True):  # the inertial navigation filter, forward and smoothed
        estimate_ins(px4.imu.slice(0, 800), px4.gps, px4.baro, InsParams(heading_tilt_aware=tilt_aware),
                     offline=not tilt_aware)
    print(f"numba loops compiled or loaded from the cache in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
