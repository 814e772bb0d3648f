"""Cost per filter step of every estimator the project has, each driven by ``run_filter`` (Kesten's
filters, the orientation MEKF, the fixed-wing EKFs and error-state UKF, the 3D quadrotor EKF and
UKF and the INS, all on the compiled engine, :mod:`quadlib.engine`).

Usage: ``python benchmarks/estimator_cost.py`` (a few minutes). Each row is the best of at least
three runs of one log, and of more while they take under a second in all (µs per step, one predict
plus that step's updates), and its ratio to the cheapest row, all measured in this run.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib import LinearKF, Measurements, run_filter
from quadlib.attitude import FILTERS, AttitudeNoise, altitude_model, baro_altitude_sensor, random_rotation
from quadlib.attitude.kesten import run_attitude_filter
from quadlib.attitude.orientation import orientation_run
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
from quadlib.nav import InsParams, estimate_ins
from quadlib.quad import SensorNoise3D, estimate_quad3d, quad3d_ekf, quad3d_ukf, simulate_run3d, square_course
from quadlib.sim import imu_samples


def best_us_per_step(run, steps: int, repeats: int = 3, budget_s: float = 1.0, most: int = 50) -> float:
    """The best of at least ``repeats`` runs, and of more (up to ``most``) while they take under
    ``budget_s`` in all: a cheap run is timed often enough that a busy moment of the machine does not
    set its row."""
    times: list[float] = []
    while len(times) < repeats or (sum(times) < budget_s and len(times) < most):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return 1e6 * min(times) / steps


def main() -> None:
    rows = []
    noise = AttitudeNoise()
    log = imu_samples(random_rotation(8.0, 250.0, np.random.default_rng(1)), noise, np.random.default_rng(2),
                      field_n=noise.field_n)
    for name, make in FILTERS.items():
        for label, compiled in (("compiled", True), ("readable run_filter", False)):
            job = lambda make=make, c=compiled: run_attitude_filter(make(noise), log, compiled=c)  # noqa: E731
            rows.append((f"Kesten {name}, {label} (250 Hz, a + m every step)", best_us_per_step(job, len(log))))
    # the whole estimate (two forward passes and the low-passes between them), per sample
    for label, compiled in (("compiled", True), ("readable run_filter", False)):
        rows.append((f"orientation MEKF, {label} (same log)",
                     best_us_per_step(lambda c=compiled: orientation_run(log, compiled=c), len(log))))

    fw_noise = FixedWingNoise()
    fw = fixedwing_samples(fixedwing_flight(rate_hz=50.0), fw_noise, np.random.default_rng(3))
    for name, factory, n, compiled in (("Salmony EKF, compiled", salmony_ekf, len(fw), True),
                                       ("Salmony EKF, readable run_filter", salmony_ekf, 1000, False),
                                       ("multiplicative EKF, compiled", multiplicative_ekf, len(fw), True),
                                       ("multiplicative EKF, readable run_filter", multiplicative_ekf, 1000, False),
                                       ("error-state UKF, compiled", error_state_ukf, len(fw), True),
                                       ("error-state UKF, readable run_filter", error_state_ukf, 200, False)):
        part = fw.slice(0, n)
        rows.append((f"fixed-wing {name} (a + m every step)",
                     best_us_per_step(lambda f=factory, p=part, c=compiled:
                                      estimate_fixedwing_attitude(p, fw_noise, f, compiled=c), n)))

    run = simulate_run3d(square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(4))
    for name, factory in (("EKF", quad3d_ekf), ("UKF", quad3d_ukf)):
        for label, compiled in (("compiled", True), ("readable run_filter", False)):
            rows.append((f"3D quadrotor {name}, {label} (50 Hz, GPS 10 Hz, mag 100 Hz)",
                         best_us_per_step(lambda f=factory, c=compiled: estimate_quad3d(
                             run.t, run.u, run.gps, run.mag, run.truth[0], filter_factory=f, compiled=c), run.t.size)))

    flight = load_px4_log()
    steps = flight.imu.t.size
    for label, params in (("heading-only", InsParams(use_gps_height=False, gps_delay_s=0.35, accel_sigma_m_s2=3.3)),
                          ("tilt-aware heading", InsParams(use_gps_height=False, gps_delay_s=0.35, accel_sigma_m_s2=3.3,
                                                           heading_tilt_aware=True))):
        for kind, compiled in (("compiled", True), ("readable run_filter", False)):
            rows.append((f"INS, {label}, {kind} (PX4 log: 83 Hz, GPS 5 Hz, baro, mag)",
                         best_us_per_step(lambda p=params, c=compiled: estimate_ins(
                             flight.imu, flight.gps, flight.baro, p, compiled=c), steps)))
    for kind, compiled in (("compiled", True), ("readable rts_smooth", False)):
        rows.append((f"INS smoothed (forward + backward pass), {kind} (same log)",
                     best_us_per_step(lambda c=compiled: estimate_ins(flight.imu, flight.gps, flight.baro, InsParams(
                         use_gps_height=False, gps_delay_s=0.35, accel_sigma_m_s2=3.3), offline=True, compiled=c),
                         steps)))

    t = np.arange(2000) * 0.004
    baro = [Measurements(baro_altitude_sensor(0.39), t[::10], np.zeros(200))]
    altitude = altitude_model(0.06, 0.001)
    rows.append(("altitude KF (250 Hz, baro 25 Hz)",
                 best_us_per_step(lambda: run_filter(LinearKF(altitude, [0, 0, 9.8], np.eye(3), 0.004), t,
                                                     np.full((2000, 1), 9.80665), baro), t.size)))

    cheapest = min(us for _, us in rows)
    print(f"{'estimator':<72} | {'µs / step':>9} | {'ratio':>6}")
    for name, us in rows:
        print(f"{name:<72} | {us:9.1f} | {us / cheapest:6.1f}")


if __name__ == "__main__":
    main()
