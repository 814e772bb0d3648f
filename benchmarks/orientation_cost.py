"""Cost per sample of the one-call orientation estimate on a long log, against VQF's C++.

Usage: ``python benchmarks/orientation_cost.py [N]`` (N samples, 200,001 by default; about a minute).
A simulated 250 Hz IMU (gyro, accelerometer, magnetometer) turning at random is estimated with
:func:`quadlib.estimate_orientation`, online and offline (both passes, the inertial low-pass, the
plausibility checks and the start included) and online in one pass without the low-pass, and by
VQF online and offline. Each row is the best of three runs, in µs per sample, with its ratio to
VQF's online cost, all measured in this run.
"""

from __future__ import annotations

import sys

import numpy as np
from estimator_cost import best_us_per_step  # the script's own folder, benchmarks/, is on its path
from vqf import VQF, offlineVQF

from quadlib.attitude import AttitudeNoise, random_rotation
from quadlib.attitude.orientation import OrientationParams, estimate_orientation
from quadlib.sim import imu_samples


def main(n: int = 200_001) -> None:
    noise = AttitudeNoise()
    rate_hz = 250.0
    log = imu_samples(random_rotation((n - 1) / rate_hz, rate_hz, np.random.default_rng(1)), noise,
                      np.random.default_rng(2), field_n=noise.field_n)
    n = len(log)
    dt = float(np.median(np.diff(log.t)))
    gyr, acc, mag = (np.ascontiguousarray(a) for a in (log.gyro, log.accel, log.mag))
    rows = [
        ("quadlib estimate_orientation, online", best_us_per_step(lambda: estimate_orientation(log), n)),
        ("quadlib estimate_orientation, offline",
         best_us_per_step(lambda: estimate_orientation(log, offline=True), n)),
        ("quadlib, one pass (accel_tau_s=None)",
         best_us_per_step(lambda: estimate_orientation(log, params=OrientationParams(accel_tau_s=None)), n)),
        ("VQF (C++), online", best_us_per_step(lambda: VQF(dt).updateBatch(gyr, acc, mag), n)),
        ("VQF (C++), offline", best_us_per_step(lambda: offlineVQF(gyr, acc, mag, dt, {}), n)),
    ]
    vqf_online = dict(rows)["VQF (C++), online"]
    print(f"{n} samples at {rate_hz:.0f} Hz")
    print(f"{'estimator':<40} | {'µs / sample':>11} | {'× VQF online':>12}")
    for name, us in rows:
        print(f"{name:<40} | {us:11.2f} | {us / vqf_online:12.1f}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))
