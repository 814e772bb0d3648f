"""Where a step of the compiled engine's time goes, on the orientation MEKF.

Usage: ``python benchmarks/engine_breakdown.py`` (about a minute, half of it compiling the timing
loops). The log is the kind :mod:`benchmarks.estimator_cost` uses, 80 s long: a simulated 250 Hz
IMU turning at random, gyro, accelerometer and magnetometer every step. The filter and its sensors are the ones
:func:`~quadlib.attitude.orientation.orientation_run` builds for its second pass, taken from its
call of :func:`~quadlib.replay.run_filter`. Printed, in µs per step, each the best of three runs
measured in this run:

* the whole forward pass (:func:`quadlib.engine.loop.filter_pass`) with no sensors, with gravity,
  with gravity and heading, and with all three (the zero-rate update applies only at rest);
* the pieces of a step alone, each called in a loop on fixed arguments: the predict, and one
  gravity (3 rows) and one heading (1 row) update, each split into the linearisation (``H`` and
  ``ẑ``), the correction (gain, Joseph's covariance, the state folded in) and the rest of the
  update (NIS, gates).

A step of the estimate's two passes is the sum of its predict and updates; what the pass costs
beyond that sum is the loop's schedule and the traces it stores.
"""

from __future__ import annotations

import time
from unittest import mock

import numpy as np
from numba import njit

from quadlib.attitude import AttitudeNoise, orientation, random_rotation
from quadlib.engine.ekf import _correct, _linearized, ekf_predict
from quadlib.engine.loop import _update
from quadlib.engine.runner import plan
from quadlib.replay import run_filter
from quadlib.sim import imu_samples

CALLS = 200_000


@njit
def _predicts(m, x, P, u, dt, n):
    q_dt, Q = 0.0, np.zeros((P.shape[0], P.shape[0]))
    for i in range(n):
        out = ekf_predict(m, x, P, u[i % u.shape[0]], dt, q_dt, Q)
        q_dt, Q = out[2], out[3]
    return out[0]


@njit
def _linearizations(m, sens, s, x, c, n):
    for _ in range(n):
        H, z_hat = _linearized(m, sens, s, x, c)
    return H


@njit
def _corrections(m, sens, s, x, P, z, c, n):
    kz = sens.dim_z[s]
    H, z_hat = _linearized(m, sens, s, x, c)
    y = z - z_hat
    for _ in range(n):
        out = _correct(m, x, P, H, y, sens.R[s, :kz, :kz], sens.corrected[s])
    return out[0]


@njit
def _updates(m, sens, sig, s, x, P, z, c, n):
    force, every = np.zeros(sens.n_groups[s], np.bool_), np.arange(sens.dim_z[s])
    for _ in range(n):
        out = _update(m, sens, sig, s, x, P, z, c, force, every)
    return out[0]


def best_us(call, per: int, repeats: int = 3) -> float:
    """The best of ``repeats`` runs of ``call()``, in µs per ``per``."""
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
    rows = []
    for label, count in (("no sensors", 0), ("gravity", 1), ("gravity, heading", 2), (", ".join(names), 3)):
        rows.append((f"forward pass, {label}", best_us(lambda c=count: run_filter(ekf, t, u, measurements[:c],
                                                                                   **options), len(t))))
    model, sensors, sigma = plan(ekf, measurements, options.get("gate_probability"))
    x, P, u = np.array(ekf.state_view(), float), np.array(ekf.P, float), np.ascontiguousarray(u, float)
    dt = float(np.median(np.diff(t)))
    _predicts(model, x, P, u, dt, 1)
    rows.append(("predict", best_us(lambda: _predicts(model, x, P, u, dt, CALLS), CALLS)))
    for s in (names.index("gravity"), names.index("heading")):
        m = measurements[s]
        usable = np.isfinite(m.z).all(axis=1)
        if m.context is not None:
            usable &= np.isfinite(m.context).all(axis=1)
        k = int(np.argmax(usable))  # the first sample the update applies
        z = np.ascontiguousarray(m.z[k], float)
        c = np.ascontiguousarray(m.context[k], float) if m.context is not None else np.zeros(1)
        for part, loop, args in (("linearisation", _linearizations, (model, sensors, s, x, c)),
                                 ("correction", _corrections, (model, sensors, s, x, P, z, c)),
                                 ("whole update", _updates, (model, sensors, sigma, s, x, P, z, c))):
            loop(*args, 1)
            rows.append((f"{names[s]} update ({sensors.dim_z[s]} rows): {part}",
                         best_us(lambda f=loop, a=args: f(*a, CALLS), CALLS)))
    print(f"orientation MEKF on the compiled engine, {len(t)} steps at 250 Hz; µs per step or per call")
    print(f"{'part':<48} | {'µs':>6}")
    for name, us in rows:
        print(f"{name:<48} | {us:6.2f}")


if __name__ == "__main__":
    main()
