"""The particle filter from the ambiguous corner start: how often it finds the right corner, how
well, and at what cost, against the number of particles, the resampling scheme and the width of
the scan likelihood.

Usage: ``python benchmarks/particle_filter.py [runs]`` (100 runs per row by default, a few
minutes). Each run simulates the drive of :func:`quadlib.perception.corner_start` with its own
seed and starts the filter from the four corner hypotheses. "Found" means the final mean pose is
within 0.5 m and 10° of the truth; the error is the median over the runs that found it; the cost
is the filter's time per run (the simulation excluded), so read it as a ratio between rows.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from quadlib.perception import corner_start, hypothesis_particles, localise, pose_error

ROWS = [(n, "systematic", 0.5) for n in (50, 100, 200, 300, 1000)] + \
       [(300, scheme, 0.5) for scheme in ("stratified", "multinomial", "residual")] + \
       [(300, "systematic", sigma) for sigma in (0.05, 0.2, 1.0)]


def trial(n: int, scheme: str, sigma_m: float, runs: int) -> tuple[float, float, float]:
    found, errors, seconds = 0, [], 0.0
    for seed in range(runs):
        rng = np.random.default_rng(seed)
        sc = corner_start(rng)
        start = time.perf_counter()
        run = localise(hypothesis_particles(sc.hypotheses, n, rng), sc.odometry, sc.ranges, sc.bearings, sc.walls,
                       sc.dt, rng, max_range_m=sc.max_range_m, sigma_m=sigma_m, scheme=scheme)
        seconds += time.perf_counter() - start
        d, a = pose_error(run.pose[-1], sc.truth[-1])
        if d < 0.5 and a < np.radians(10.0):
            found += 1
            errors.append(d)
    return found / runs, float(np.median(errors)) if errors else float("nan"), seconds / runs


def main(runs: int = 100) -> None:
    print(f"{runs} runs per row")
    print(f"{'particles':>9} {'scheme':>11} {'σ [m]':>6} | {'found':>6} {'error [m]':>9} {'ms/run':>7} {'ms/step':>8}")
    steps = corner_start(np.random.default_rng(0)).truth.shape[0]
    for n, scheme, sigma in ROWS:
        share, err, sec = trial(n, scheme, sigma, runs)
        print(f"{n:9d} {scheme:>11} {sigma:6.2f} | {100 * share:5.0f}% {err:9.3f} {1e3 * sec:7.0f} "
              f"{1e3 * sec / steps:8.2f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
