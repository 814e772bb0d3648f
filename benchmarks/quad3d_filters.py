"""Chapter 11's EKF and UKF on the same 20 simulated flights: accuracy, consistency and cost.

Usage: ``python benchmarks/quad3d_filters.py`` (about a minute). Chapter 11 prints the same table
from the compiled filters; this script runs each filter both compiled and readable (``run_filter``)
and prints the seconds per flight with their ratios to the compiled EKF, measured in the same run.
"""

from __future__ import annotations

import time

import numpy as np

from quadlib.geometry.rotations import wrap_angle
from quadlib.quad.estimate import Quad3DParams, estimate_quad3d, quad3d_ekf, quad3d_ukf
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.scenario import simulate_run3d


def main(n_flights: int = 20, seed: int = 8) -> None:
    rng = np.random.default_rng(seed)
    flight, noise, decimate = square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), 10
    dt = decimate * flight.dt
    params = Quad3DParams()  # chapter 11's
    P0 = params.P0
    factories = {"EKF": (quad3d_ekf, True), "EKF, run_filter": (quad3d_ekf, False),
                 "UKF": (quad3d_ukf, True), "UKF, run_filter": (quad3d_ukf, False)}
    errs = {name: [] for name in factories}
    sigmas = {name: [] for name in factories}
    seconds = dict.fromkeys(factories, 0.0)
    largest_gap = 0.0
    for _ in range(n_flights):
        run = simulate_run3d(flight, noise, rng, decimate=decimate, tau=5.0)
        x0 = run.truth[0] + rng.normal(size=7) * np.sqrt(np.diag(P0))
        estimates = {}
        for name, (factory, compiled) in factories.items():
            start = time.perf_counter()
            res = estimate_quad3d(run.t, run.u, run.gps, run.mag, x0, params, filter_factory=factory, compiled=compiled)
            seconds[name] += time.perf_counter() - start
            e = res.x - run.truth
            e[:, 6] = wrap_angle(e[:, 6])
            errs[name].append(e)
            sigmas[name].append(res.sigma)
            estimates[name] = res.x
        gap = estimates["UKF"] - estimates["EKF"]
        gap[:, 6] = wrap_angle(gap[:, 6])
        largest_gap = max(largest_gap, np.abs(gap).max())
    print(f"{n_flights} flights of {flight.t[-1]:.0f} s, filter at {1 / dt:.0f} Hz, GPS 10 Hz, magnetometer 100 Hz")
    print(f"{'filter':<15} | {'pos [m]':>7} {'vel [m/s]':>9} {'yaw [deg]':>9} | {'inside ±1σ pos':>14} {'vel':>5} "
          f"{'yaw':>5} | {'s / flight':>10} {'ratio':>6}")
    for name in factories:
        e, s = np.concatenate(errs[name]), np.concatenate(sigmas[name])
        inside = np.abs(e) < s
        pos, vel = np.sqrt(np.mean(np.sum(e[:, :3] ** 2, axis=1))), np.sqrt(np.mean(np.sum(e[:, 3:6] ** 2, axis=1)))
        print(f"{name:<15} | {pos:7.3f} {vel:9.3f} {np.degrees(np.sqrt(np.mean(e[:, 6] ** 2))):9.2f} | "
              f"{inside[:, :3].mean():14.0%} {inside[:, 3:6].mean():5.0%} {inside[:, 6].mean():5.0%} | "
              f"{seconds[name] / n_flights:10.2f} {seconds[name] / seconds['EKF']:6.1f}")
    print(f"largest |UKF − EKF| over all flights and states: {largest_gap:.1e}")


if __name__ == "__main__":
    main()
