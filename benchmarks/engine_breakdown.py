"""Where the compiled engine's time goes, on the orientation MEKF: sensor by sensor.

Usage: ``python benchmarks/engine_breakdown.py`` (about half a minute, with the compiles of the
filters it times). The log is the kind :mod:`benchmarks.estimator_cost` uses, 80 s long: a simulated
250 Hz IMU turning at random, gyro, accelerometer and magnetometer every step. The filter and its
sensors are the ones :func:`~quadlib.attitude.orientation.orientation_run` builds for its second
pass, taken from its call of :func:`~quadlib.replay.run_filter`. Printed, in µs per step, each the
best of three runs measured in this run: the whole forward pass with no sensors (the predict and the
loop), with gravity, with gravity and heading, and with all three (the zero-rate update applies only
at rest), then the RTS backward pass over the last. Each row's difference from the one before is
what that sensor's updates cost a step.
"""

from __future__ import annotations

import time
from unittest import mock

import numpy as np

from quadlib.attitude import AttitudeNoise, orientation, random_rotation
from quadlib.replay import rts_smooth, run_filter
from quadlib.sim import imu_samples


def best_us(call, per: int, repeats: int = 3) -> float:
    """The best of ``repeats`` runs of ``call()`` after one to compile it, in µs per ``per``."""
    call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return 1e6 * min(times) / per


def main() -> None:
    noise = AttitudeNoise()
    log = imu_samples(random_rotation(80.0, 250.0, np.random.default_rng(1)), noise, np.random.default_rng(2),
                      field_n=noise.field_n)
    with mock.patch.object(orientation, "run_filter", wraps=run_filter) as spy:
        orientation.orientation_run(log)
    (ekf, t, u, measurements), options = spy.call_args_list[-1]  # the second pass
    names = [m.sensor.name for m in measurements]
    start = (ekf.estimate, ekf.P.copy())
    rows = []

    def forward(count: int):
        ekf.continue_from(*start, ekf.reused_noise)
        return run_filter(ekf, t, u, measurements[:count], **(options | {"engine": "compiled"}))

    for label, count in (("no sensors", 0), ("gravity", 1), ("gravity, heading", 2), (", ".join(names), 3)):
        rows.append((f"forward pass, {label}", best_us(lambda c=count: forward(c), len(t))))
    run = forward(3)
    rows.append(("RTS backward pass", best_us(lambda: rts_smooth(ekf.model, run, u, engine="compiled"), len(t))))
    print(f"orientation MEKF on the compiled engine, {len(t)} steps at 250 Hz; µs per step")
    print(f"{'part':<48} | {'µs':>6}")
    for name, us in rows:
        print(f"{name:<48} | {us:6.2f}")


if __name__ == "__main__":
    main()
