"""Batched against per-run Monte Carlo: the linear KF (chapter 8's 1D quadrotor) and the EKF and
UKF (chapter 9's 2D quadrotor near a wall).

Usage: ``python benchmarks/montecarlo_batch.py``. N flights on a 50 Hz (1D) or 20 Hz (2D) grid, a
10 Hz range sensor with dropouts and outliers, a χ² gate. Two tables, best of three, ratios
measured in this run: the filters alone (``run_filter`` per flight against ``run_batch`` on the same
samples), and the whole ``run_monte_carlo`` call, whose simulation of the flights is the same in both.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib import LinearKF, ModelEKF, ModelUKF, run_filter
from quadlib.analysis.batched import run_batch
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
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


def cases():
    """Name, filter factory, truth model, sensor, x0, P0, t, u of each benchmarked filter."""
    t1 = np.arange(0.0, 5.0 + 1e-9, 0.02)
    line, ranger = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    yield ("linear KF", lambda x0, P0: LinearKF(line, x0, P0, 0.02), line, ranger, [0.0, 1.0], np.eye(2) * 0.25, t1,
           np.zeros((t1.size, 1)))
    t2 = np.arange(0.0, 3.0 + 1e-9, 0.05)
    planar, wall = quad2d_model(0.2, np.radians(3.0)), quad2d_range_sensor(0.01, wall_y_m=5.0, rate_hz=10)
    u2 = -np.radians(15.0) * np.cos(2.5 * t2)[:, None]
    P0 = np.diag([np.radians(3.0) ** 2, 0.05**2, 0.1**2])
    for name, kind in (("EKF", ModelEKF), ("UKF", ModelUKF)):
        yield name, lambda x0, P0, k=kind: k(planar, x0, P0, 0.05), planar, wall, [0.0, 0.0, 3.0], P0, t2, u2


def filters_alone(case, n: int, rng) -> tuple[float, float]:
    """Seconds of ``run_filter`` per flight and of ``run_batch``, on the same ``n`` flights' samples."""
    _, make, model, sensor, x0, P0, t, u = case
    samples = [corrupt([sample_sensor(sensor, t, simulate_model(model, x0, t, u, rng), rng)], rng) for _ in range(n)]
    loop = best_seconds(lambda: [run_filter(make(x0, P0), t, u, run, gate_probability=0.999) for run in samples])
    batch = best_seconds(lambda: run_batch(make(x0, P0), np.tile(x0, (n, 1)), t, u, samples, 0.999))
    return loop, batch


def whole_call(case, n: int) -> tuple[float, float]:
    """Seconds of ``run_monte_carlo`` per flight and batched."""
    name, make, model, sensor, x0, P0, t, u = case

    def run(batched):
        return run_monte_carlo({name: make}, model, [sensor], x0, P0, t, u, n, np.random.default_rng(0),
                               corrupt=corrupt, gate_probability=0.999, batched=batched)

    return best_seconds(lambda: run(False)), best_seconds(lambda: run(True))


def main() -> None:
    rng = np.random.default_rng(0)
    for title, measure in (("filters alone", lambda case, n: filters_alone(case, n, rng)),
                           ("run_monte_carlo, simulation included", whole_call)):
        print(title)
        print(f"{'filter':<9} | {'flights':>7} | {'per run [s]':>11} | {'batched [s]':>11} | {'ratio':>6}")
        for case in cases():
            for n in (20, 100):
                loop, batch = measure(case, n)
                print(f"{case[0]:<9} | {n:7d} | {loop:11.3f} | {batch:11.3f} | {loop / batch:6.1f}")


if __name__ == "__main__":
    main()
