"""How many argument checks one ``estimate_orientation`` call makes, by check.

Usage: ``python benchmarks/validation_calls.py`` (a few seconds). Every check of
:mod:`quadlib.validation` is counted wherever a quadlib module calls it, over one call of
``estimate_orientation(t, gyr, acc, mag)`` on a simulated 10 s log at 100 Hz (after a first call,
so that what is built once a process is not counted). Rows ``check | calls``, then the total.
"""

from __future__ import annotations

import sys
from collections import Counter

import numpy as np

import quadlib
import quadlib.validation as validation
from quadlib.attitude import random_rotation
from quadlib.attitude.orientation import estimate_orientation
from quadlib.constants import earth_field_ned
from quadlib.imu import ImuNoise
from quadlib.sim import imu_samples


def counted_checks() -> Counter:
    """Replace every check in every loaded quadlib module by one that counts its calls."""
    counts = Counter()
    names = [n for n in dir(validation) if n.startswith("as_") or n == "check_fields"]
    originals = {n: getattr(validation, n) for n in names}

    def counting(name, check):
        def call(*args, **kwargs):
            counts[name] += 1
            return check(*args, **kwargs)
        return call

    wrapped = {n: counting(n, f) for n, f in originals.items()}
    for module in list(sys.modules.values()):
        if getattr(module, "__name__", "").startswith(quadlib.__name__):
            for n, f in originals.items():
                if getattr(module, n, None) is f:
                    setattr(module, n, wrapped[n])
    return counts


def main() -> None:
    counts = counted_checks()
    log = imu_samples(random_rotation(10.0, 100.0, np.random.default_rng(0)),
                      ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3), np.random.default_rng(1),
                      field_n=earth_field_ned(50.0, np.radians(65.0)))
    estimate_orientation(log.t, log.gyro, log.accel, log.mag)
    counts.clear()
    estimate_orientation(log.t, log.gyro, log.accel, log.mag)
    print(f"{'check':<24} | {'calls':>5}")
    for name, calls in counts.most_common():
        print(f"{name:<24} | {calls:5d}")
    print(f"{'all checks':<24} | {sum(counts.values()):5d}")


if __name__ == "__main__":
    main()
