"""Does a fixed-wing filter diverge on clean simulated data? Seeds × sample rates, peak attitude error.

Usage: ``python benchmarks/fixedwing_divergence.py [seeds] [rates_hz] [filters]``, e.g.
``python benchmarks/fixedwing_divergence.py 50 25,100,500,1000 EKF,MEKF`` (the full run takes about
half an hour per filter on a 2-core machine). A run diverged when its attitude error exceeds 20°
after the first 5 s. Prints one row per filter and rate.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from quadlib.analysis.metrics import attitude_error
from quadlib.fixedwing import (
    FixedWingNoise,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    multiplicative_ekf,
    salmony_ekf,
)

FILTERS = {"EKF": salmony_ekf, "MEKF": multiplicative_ekf, "ES-UKF": error_state_ukf}


def main(n_seeds: int = 12, rates=(25.0, 100.0), names=("EKF", "MEKF")) -> None:
    noise = FixedWingNoise()
    print(f"{'filter':<7} {'rate [Hz]':>9} | {'diverged (>20°)':>15} | {'median peak [deg]':>17} | "
          f"{'worst peak [deg]':>16} | {'s / flight':>10}")
    for rate in rates:
        flight = fixedwing_flight(rate_hz=rate)
        late = flight.t > 5.0
        for name in names:
            peaks, seconds = [], 0.0
            for seed in range(n_seeds):
                log = fixedwing_samples(flight, noise, np.random.default_rng([12, seed]))
                start = time.perf_counter()
                run = estimate_fixedwing_attitude(log, noise, FILTERS[name])
                seconds += time.perf_counter() - start
                peaks.append(np.degrees(attitude_error(run.x[:, :4], flight.q_nb)[late].max()))
            peaks = np.array(peaks)
            print(f"{name:<7} {rate:9.0f} | {np.sum(peaks > 20.0):7d} of {n_seeds:<4d} | {np.median(peaks):17.2f} | "
                  f"{peaks.max():16.2f} | {seconds / n_seeds:10.2f}", flush=True)


if __name__ == "__main__":
    args = sys.argv[1:]
    main(int(args[0]) if args else 12, tuple(float(r) for r in args[1].split(",")) if len(args) > 1 else (25.0, 100.0),
         tuple(args[2].split(",")) if len(args) > 2 else ("EKF", "MEKF"))
