"""Chapter 15's estimators on 20 simulated fixed-wing flights: accuracy, bias and cost.

Usage: ``python benchmarks/fixedwing_filters.py`` (about 20 s; the multiplicative EKF has no
compiled twin). Chapter 15 prints the same table for the EKF, the error-state UKF and the
complementary filter; this one adds the multiplicative EKF and the seconds each takes per flight.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib.analysis.metrics import angle_error
from quadlib.fixedwing import (
    FixedWingNoise,
    complementary_attitude,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.geometry.quaternion import quat_to_euler

FILTERS = {"EKF": salmony_ekf, "MEKF": multiplicative_ekf, "ES-UKF": error_state_ukf}


def main(n_flights: int = 20, seed: int = 12) -> None:
    flight, noise = fixedwing_flight(rate_hz=25.0), FixedWingNoise()
    settled = flight.t > 5.0
    names = (*FILTERS, "complementary")
    sq = {name: [] for name in names}
    bias_err = {name: [] for name in FILTERS}
    seconds = dict.fromkeys(names, 0.0)
    for i in range(n_flights):
        log = fixedwing_samples(flight, noise, np.random.default_rng([seed, i]))
        true_bias = np.mean(log.gyro[-25:] - flight.omega_b[-25:], axis=0)
        for name in names:
            start = time.perf_counter()
            if name in FILTERS:
                run = estimate_fixedwing_attitude(log, noise, FILTERS[name])
                euler = np.column_stack(quat_to_euler(run.x[:, :4]))
                bias_err[name].append(np.abs(run.x[-1, 4:] - true_bias).max())
            else:
                euler = complementary_attitude(log, noise.declination_rad)
            seconds[name] += time.perf_counter() - start
            sq[name].append(angle_error(euler, flight.euler)[settled] ** 2)
    print(f"{n_flights} flights of {flight.t[-1]:.0f} s at {1 / flight.dt:.0f} Hz (RMSE after 5 s)")
    print(f"{'estimator':<14} | {'roll [deg]':>10} {'pitch':>7} {'yaw':>7} | {'final bias error [mrad/s]':>26} | "
          f"{'s / flight':>10} {'ratio':>6}")
    for name in names:
        rmse = np.degrees(np.sqrt(np.mean(np.concatenate(sq[name]), axis=0)))
        b = f"{1000 * np.mean(bias_err[name]):26.2f}" if name in bias_err else f"{'–':>26}"
        print(f"{name:<14} | {rmse[0]:10.2f} {rmse[1]:7.2f} {rmse[2]:7.2f} | {b} | {seconds[name] / n_flights:10.2f} "
              f"{seconds[name] / seconds['EKF']:6.1f}")


if __name__ == "__main__":
    main()
