"""Batched against per-run Monte Carlo for a linear Kalman filter (chapter 5's 1D quadrotor).

Usage: ``python benchmarks/montecarlo_batch.py``. N flights of 5 s at 50 Hz (a 10 Hz range sensor
with dropouts and outliers, a χ² gate). Two tables, best of three, ratios measured in this run:
the filters alone (``run_filter`` per flight against ``run_linear_batch`` on the same samples), and
the whole ``run_monte_carlo`` call, whose simulation of the flights is the same in both.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib import LinearKF, run_filter
from quadlib.analysis.batched import run_linear_batch
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.samples import Measurements
from quadlib.sim.simulate import sample_sensor, simulate_model


def corrupt(samples, rng):
    out = []
    for m in samples:
        z = m.z.copy()
        z[rng.random(z.shape[0]) < 0.2] = np.nan
        spikes = rng.random(z.shape[0]) < 0.1
        z[spikes] += 10 * rng.standard_normal((spikes.sum(), z.shape[1]))
        out.append(Measurements(m.sensor, m.t, z))
    return out


def best_seconds(fn, repeats: int = 3) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    t = np.arange(0.0, 5.0 + 1e-9, 0.02)
    u = np.zeros((t.size, 1))
    filters = {"kf": lambda x0, P0: LinearKF(model, x0, P0, 0.02)}

    def run(n, batched):
        return run_monte_carlo(filters, model, [sensor], [0.0, 1.0], np.eye(2) * 0.25, t, u, n,
                               np.random.default_rng(0), corrupt=corrupt, gate_probability=0.999, batched=batched)

    rng = np.random.default_rng(0)
    print("filters alone")
    print(f"{'flights':>7} | {'per run [s]':>11} | {'batched [s]':>11} | {'ratio':>6}")
    for n in (20, 100):
        samples = [corrupt([sample_sensor(sensor, t, simulate_model(model, [0.0, 1.0], t, u, rng), rng)], rng)
                   for _ in range(n)]
        kf = LinearKF(model, [0.0, 1.0], np.eye(2) * 0.25, 0.02)
        loop = best_seconds(lambda s=samples: [run_filter(LinearKF(model, [0.0, 1.0], np.eye(2) * 0.25, 0.02), t, u,
                                                          run, gate_probability=0.999) for run in s])
        batch = best_seconds(lambda n=n, s=samples, kf=kf: run_linear_batch(kf, np.tile([0.0, 1.0], (n, 1)), t, u, s,
                                                                             0.999))
        print(f"{n:7d} | {loop:11.3f} | {batch:11.3f} | {loop / batch:6.1f}")
    print("run_monte_carlo, simulation included")
    print(f"{'flights':>7} | {'per run [s]':>11} | {'batched [s]':>11} | {'ratio':>6}")
    for n in (20, 100):
        loop, batch = best_seconds(lambda n=n: run(n, False)), best_seconds(lambda n=n: run(n, True))
        print(f"{n:7d} | {loop:11.3f} | {batch:11.3f} | {loop / batch:6.1f}")

if __name__ == "__main__":
    main()
