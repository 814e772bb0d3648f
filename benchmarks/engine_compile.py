"""What a filter's first run costs: the compile of its engine, at LLVM's -O1 (the engine's choice)
and at numba's default -O3, and what each compiled loop then costs per step.

Usage: ``python benchmarks/engine_compile.py`` (about five minutes on 2 cores). Each filter runs in a
new process with an empty cache of filters (``QUADLIB_CACHE_DIR``; quadlib's own kernels stay
compiled, as after ``make``): the first run's seconds beyond a later run's are the compile, the best
of three later runs the cost of one run (a 40 s, 250 Hz log; the fixed-wing flight at 50 Hz). Each
row has its ratio to the -O3 row, all measured in this run.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

FILTERS = {
    "orientation MEKF": "from quadlib.attitude.orientation import estimate_orientation as run\n"
                        "call = lambda: run(LOG)",
    "Kesten's QKF": "from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter\n"
                    "call = lambda: run_attitude_filter(FILTERS['QKF'](AttitudeNoise()), LOG)",
    "fixed-wing error-state UKF": "from quadlib.fixedwing import FixedWingNoise, error_state_ukf, "
                                  "estimate_fixedwing_attitude, fixedwing_flight, fixedwing_samples\n"
                                  "import numpy as np\n"
                                  "FW = fixedwing_samples(fixedwing_flight(rate_hz=50.0), FixedWingNoise(), "
                                  "np.random.default_rng(2))\n"
                                  "call = lambda: estimate_fixedwing_attitude(FW, FixedWingNoise(), error_state_ukf)",
}

PROGRAM = """
import time, numpy as np
from quadlib.attitude import AttitudeNoise, random_rotation
from quadlib.sim import imu_samples
noise = AttitudeNoise()
LOG = imu_samples(random_rotation(40.0, 250.0, np.random.default_rng(1)), noise, np.random.default_rng(2),
                  field_n=noise.field_n)
{setup}
start = time.perf_counter(); call(); first = time.perf_counter() - start
best = []
for _ in range(3):
    start = time.perf_counter(); run_ = call(); best.append(time.perf_counter() - start)
print(first - min(best), min(best))
"""


def measure(setup: str, level: int) -> tuple[float, float]:
    """Compile seconds and seconds per run of ``setup``'s call, in a new process."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, QUADLIB_CACHE_DIR=cache, QUADLIB_ENGINE_OPT=str(level))
        out = subprocess.run([sys.executable, "-c", PROGRAM.format(setup=setup)], env=env, check=True,
                             capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1])


def main() -> None:
    print(f"{'filter, setting':<48} | {'value':>8} | {'ratio':>6}")
    for name, setup in FILTERS.items():
        results = {level: measure(setup, level) for level in (3, 1)}
        for what, column, scale in (("compile [s]", 0, 1.0), ("one run [ms]", 1, 1e3)):
            for level in (3, 1):
                value = results[level][column]
                print(f"{f'{name}, O{level}, {what}':<48} | {scale * value:8.2f} | {value / results[3][column]:6.2f}")


if __name__ == "__main__":
    main()
