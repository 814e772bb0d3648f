"""Kesten's Fig. 5.2 at full length: the five attitude filters on a 2-minute, 250 Hz tumble.

Usage: ``python benchmarks/attitude_filters.py [seconds]`` (default 120 s of motion, about 15 s of
computing with the compiled filters). Prints the mean squared attitude error for magnetometer
periods ``τ_m = k τ_a``, k = 1…5, with the thesis's process noise (τ σ²_ω) and with the corrected
one ((σ_ω τ)², erratum E15), the largest quaternion norm error, and each filter's cost per step,
measured in the same run. Writes the errors to ``benchmarks/results/attitude_filters.csv`` (a test
recomputes one entry). Chapter 13 computes the same tables itself, from the same seeds.
"""

from __future__ import annotations

import csv
import sys
import time
from pathlib import Path

import numpy as np

from quadlib.analysis.metrics import attitude_error
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.tumble import random_rotation
from quadlib.sim.imu import imu_samples

RESULTS = Path(__file__).resolve().parent / "results" / "attitude_filters.csv"
NOISES = {"thesis": True, "corrected": False}  # process noise Δt σ²_ω as printed, or (σ_ω Δt)² (E15)


def _log(motion, noise, k: int, seed: int):
    return imu_samples(motion, noise, np.random.default_rng([seed, k]), field_n=noise.field_n, mag_every=k)


def _mse_deg2(estimate, motion) -> float:
    """Mean squared attitude error [deg²] after the first 2 s."""
    err = np.degrees(attitude_error(estimate, motion.q_nb))
    return float(np.mean(err[motion.t > 2.0] ** 2))


def fig_5_2_entry(name: str, noise_label: str, k: int, seconds: float = 120.0, seed: int = 10) -> float:
    """One entry of the table, computed alone."""
    motion = random_rotation(seconds, 250.0, np.random.default_rng(seed))
    noise = AttitudeNoise(thesis_process_noise=NOISES[noise_label])
    return _mse_deg2(run_attitude_filter(FILTERS[name](noise), _log(motion, noise, k, seed)).q_nb, motion)


def main(seconds: float = 120.0, seed: int = 10) -> None:
    motion = random_rotation(seconds, 250.0, np.random.default_rng(seed))
    t = motion.t
    cost = {name: [0.0, 0] for name in FILTERS}
    worst_norm = dict.fromkeys(FILTERS, 0.0)
    rows = []
    for noise_label, label in (("thesis", "thesis's process noise Δt σ²_ω"),
                               ("corrected", "corrected process noise (σ_ω Δt)²")):
        noise = AttitudeNoise(thesis_process_noise=NOISES[noise_label])
        print(f"\nmean squared attitude error [deg²], {seconds:g} s at 250 Hz, {label}")
        print(f"{'k':>2} | " + " | ".join(f"{name:>8}" for name in FILTERS))
        for k in range(1, 6):
            log = _log(motion, noise, k, seed)
            row = []
            for name, make in FILTERS.items():
                start = time.perf_counter()
                est = run_attitude_filter(make(noise), log).q_nb
                cost[name][0] += time.perf_counter() - start
                cost[name][1] += len(t)
                worst_norm[name] = max(worst_norm[name], np.abs(np.linalg.norm(est, axis=1) - 1.0).max())
                row.append(_mse_deg2(est, motion))
                rows.append({"noise": noise_label, "k": k, "filter": name, "mse_deg2": f"{row[-1]:.6g}",
                             "seconds": f"{seconds:g}", "seed": seed})
            print(f"{k:2d} | " + " | ".join(f"{v:8.5f}" for v in row))
    if seconds == 120.0:
        RESULTS.parent.mkdir(exist_ok=True)
        with RESULTS.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        print(f"\nwritten: {RESULTS}")
    print(f"\nlargest |‖q‖ − 1| over all {len(t)}-step runs: " + ", ".join(
        f"{name} {v:.1e}" for name, v in worst_norm.items()))
    fastest = min(c / n for c, n in cost.values())
    print("\ncost per step: " + ", ".join(f"{name} {1e6 * c / n:.0f} µs ({c / n / fastest:.1f}×)"
                                          for name, (c, n) in cost.items()))


if __name__ == "__main__":
    main(float(sys.argv[1]) if len(sys.argv) > 1 else 120.0)
