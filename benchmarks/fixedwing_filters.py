"""Chapter 12's estimators on 20 simulated fixed-wing flights: accuracy, bias and cost.

Usage: ``python benchmarks/fixedwing_filters.py`` (a few minutes: the error-state UKF costs several
milliseconds per step). The chapter shows fewer flights to stay within its 20 s budget.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib.fixedwing.run import ESTIMATORS, run_estimator
from quadlib.fixedwing.sim import FixedWingNoise, fixedwing_flight, fixedwing_samples
from quadlib.geometry.rotations import wrap_angle


def main(n_flights: int = 20, seed: int = 12) -> None:
    flight, noise = fixedwing_flight(rate_hz=25.0), FixedWingNoise()
    settled = flight.t > 5.0
    sq = {name: [] for name in ESTIMATORS}
    bias_err = {name: [] for name in ESTIMATORS}
    seconds = dict.fromkeys(ESTIMATORS, 0.0)
    for i in range(n_flights):
        samples = fixedwing_samples(flight, noise, np.random.default_rng([seed, i]))
        true_bias = np.mean(samples.gyro[-25:] - flight.omega_b[-25:], axis=0)
        for name in ESTIMATORS:
            start = time.perf_counter()
            euler, bias = run_estimator(name, samples, noise, flight.dt, n_still=50)
            seconds[name] += time.perf_counter() - start
            sq[name].append(wrap_angle(euler - flight.euler)[settled] ** 2)
            if bias is not None:
                bias_err[name].append(np.abs(bias[-1] - true_bias).max())
    print(f"{n_flights} flights of {flight.t[-1]:.0f} s at {1 / flight.dt:.0f} Hz (RMSE after 5 s)")
    print(f"{'estimator':<14} | {'roll [deg]':>10} {'pitch':>7} {'yaw':>7} | {'final bias error [mrad/s]':>26} | "
          f"{'s / flight':>10} {'ratio':>6}")
    for name in ESTIMATORS:
        rmse = np.degrees(np.sqrt(np.mean(np.concatenate(sq[name]), axis=0)))
        b = f"{1000 * np.mean(bias_err[name]):26.2f}" if bias_err[name] else f"{'–':>26}"
        print(f"{name:<14} | {rmse[0]:10.2f} {rmse[1]:7.2f} {rmse[2]:7.2f} | {b} | {seconds[name] / n_flights:10.2f} "
              f"{seconds[name] / seconds['EKF']:6.1f}")


if __name__ == "__main__":
    main()
