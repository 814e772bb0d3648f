"""The particle filter from the ambiguous corner start: how often it finds the right corner, how
well, and at what cost, against the number of particles, the resampling scheme and the width of
the scan likelihood.

Usage: ``python benchmarks/particle_filter.py [runs]`` (100 runs per row by default, a few
minutes); writes ``benchmarks/results/particle_filter.csv`` (shown in chapter 20; the share found
and the error are reproducible, the milliseconds are this machine's). Each row is
:func:`quadlib.perception.corner_trials`: every run simulates the drive of ``corner_start`` with its
own seed and starts the filter from the four corner hypotheses. "Found" means the final mean pose
is within 0.5 m and 10° of the truth; the error is the median over the runs that found it; the
cost is the filter's time per run (the simulation excluded), so read it as a ratio between rows.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

from quadlib.perception import corner_start, corner_trials

ROWS = [(n, "systematic", 0.5) for n in (50, 100, 200, 300, 1000)] + \
       [(300, scheme, 0.5) for scheme in ("stratified", "multinomial", "residual")] + \
       [(300, "systematic", sigma) for sigma in (0.05, 0.2, 1.0)]


RESULTS = Path(__file__).resolve().parent / "results" / "particle_filter.csv"


def main(runs: int = 100) -> None:
    print(f"{runs} runs per row")
    print(f"{'particles':>9} {'scheme':>11} {'σ [m]':>6} | {'found':>6} {'error [m]':>9} {'ms/run':>7} {'ms/step':>8}")
    steps = corner_start(np.random.default_rng(0)).truth.shape[0]
    rows = []
    for n, scheme, sigma in ROWS:
        share, err, sec = corner_trials(n, runs, scheme=scheme, sigma_m=sigma)
        print(f"{n:9d} {scheme:>11} {sigma:6.2f} | {100 * share:5.0f}% {err:9.3f} {1e3 * sec:7.0f} "
              f"{1e3 * sec / steps:8.2f}")
        rows.append({"particles": n, "scheme": scheme, "sigma_m": sigma, "runs": runs, "found": f"{share:.2f}",
                     "median_error_m": f"{err:.3f}", "ms_per_run": f"{1e3 * sec:.0f}"})
    with RESULTS.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100)
