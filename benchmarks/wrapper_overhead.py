"""Per-step cost of quadlib's filter wrappers against bare filterpy and the textbook numpy versions.

Usage: ``python benchmarks/wrapper_overhead.py``. The problem is the 2D quadrotor of Tellex §6
(nonlinear transition and range measurement), one predict and one update per step.

Variants, each running the same log and keeping the mean and covariance of every step (and,
except for the textbook versions, the innovation and its covariance, as ``run_filter`` does):

* bare filterpy — the shortest *correct* filterpy code (an EKF subclass whose ``predict_x``
  applies ``g``; a UKF with ``fx(x, dt, u)``);
* quadlib ``run_filter`` — validates the whole log once, then steps without per-call checks;
* quadlib checked calls — a loop of ``predict`` / ``update_sensor``, which validate every argument
  and result (what interactive use costs);
* textbook numpy — ``quadlib.reference`` (Tellex Algorithms 2 and 3).

The table shows the best of several interleaved repeats and ratios measured in this run, and the
largest difference of each variant's estimates from bare filterpy. Asserts nothing.
"""

from __future__ import annotations

import time

import numpy as np
from filterpy.kalman import ExtendedKalmanFilter, MerweScaledSigmaPoints, UnscentedKalmanFilter

from quadlib import Measurements, ModelEKF, ModelUKF, run_filter
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
from quadlib.reference import ekf_predict, ekf_update, ukf_predict, ukf_update
from quadlib.sim.simulate import sample_sensor, simulate_model

DT, STEPS, REPEATS = 0.02, 2000, 7
ALPHA, BETA, KAPPA = 0.5, 2.0, 0.0
MODEL, SENSOR = quad2d_model(0.2, 0.01), quad2d_range_sensor(0.05)
X0, P0 = np.array([0.0, 0.0, 0.0]), np.diag([0.01, 0.1, 0.1])


def make_log():
    """Inputs u[k] over step k and the range sample z[k] taken at its end."""
    rng = np.random.default_rng(0)
    t = DT * np.arange(STEPS + 1)
    u = 0.2 * np.sin(0.8 * t)[:, None]
    x = simulate_model(MODEL, X0, t, u, rng)
    return u[:-1], sample_sensor(SENSOR, t[1:], x[1:], rng).z


class BareEKF(ExtendedKalmanFilter):
    def predict_x(self, u=0):
        self.x = MODEL.g(self.x[:, 0], u, DT).reshape(-1, 1)


def run_bare_ekf(us, zs):
    f = BareEKF(dim_x=3, dim_z=1)
    f.x, f.P, f.R, f.Q = X0.reshape(-1, 1).copy(), P0.copy(), SENSOR.R, MODEL.Q(DT)
    hj = lambda x: SENSOR.H(x[:, 0])  # noqa: E731
    hx = lambda x: SENSOR.h(x[:, 0]).reshape(-1, 1)  # noqa: E731
    xs, Ps, ys, Ss = np.empty((STEPS, 3)), np.empty((STEPS, 3, 3)), np.empty((STEPS, 1)), np.empty((STEPS, 1, 1))
    for k, (u, z) in enumerate(zip(us, zs, strict=True)):
        f.F = MODEL.G(f.x[:, 0], u, DT)
        f.predict(u)
        f.update(z.reshape(-1, 1), hj, hx)
        xs[k], Ps[k], ys[k], Ss[k] = f.x[:, 0], f.P, f.y[:, 0], f.S
    return xs


def run_bare_ukf(us, zs):
    pts = MerweScaledSigmaPoints(3, alpha=ALPHA, beta=BETA, kappa=KAPPA)
    f = UnscentedKalmanFilter(dim_x=3, dim_z=1, dt=DT, hx=SENSOR.h, fx=lambda x, dt, u: MODEL.g(x, u, dt),
                              points=pts)
    f.x, f.P, f.R, f.Q = X0.copy(), P0.copy(), SENSOR.R, MODEL.Q(DT)
    xs, Ps, ys, Ss = np.empty((STEPS, 3)), np.empty((STEPS, 3, 3)), np.empty((STEPS, 1)), np.empty((STEPS, 1, 1))
    for k, (u, z) in enumerate(zip(us, zs, strict=True)):
        f.predict(u=u)
        f.update(z)
        xs[k], Ps[k], ys[k], Ss[k] = f.x, f.P, f.y, f.S
    return xs


def make_filter(cls):
    return cls(MODEL, X0, P0, DT) if cls is ModelEKF else cls(MODEL, X0, P0, DT, alpha=ALPHA, beta=BETA, kappa=KAPPA)


def run_checked(cls, us, zs):
    f = make_filter(cls)
    xs, Ps, ys, Ss = np.empty((STEPS, 3)), np.empty((STEPS, 3, 3)), np.empty((STEPS, 1)), np.empty((STEPS, 1, 1))
    for k, (u, z) in enumerate(zip(us, zs, strict=True)):
        f.predict(u)
        inn = f.update_sensor(SENSOR, z)
        xs[k], Ps[k], ys[k], Ss[k] = f.estimate, f.P, inn.y, inn.S
    return xs


def run_replay(cls, us, zs):
    t = DT * np.arange(STEPS + 1)  # sample k is taken at the end of step k
    run = run_filter(make_filter(cls), t, np.vstack([us, us[-1:]]), [Measurements(SENSOR, t[1:], zs)])
    return run.x[1:]


def run_textbook(predict, update, args, us, zs):
    mu, Sigma = X0.copy(), P0.copy()
    xs, Ps = np.empty((STEPS, 3)), np.empty((STEPS, 3, 3))
    for k, (u, z) in enumerate(zip(us, zs, strict=True)):
        mu, Sigma = update(SENSOR, *predict(MODEL, mu, Sigma, u, DT, *args), z, *args)
        xs[k], Ps[k] = mu, Sigma
    return xs


VARIANTS = {
    "EKF  bare filterpy": run_bare_ekf,
    "EKF  quadlib run_filter": lambda us, zs: run_replay(ModelEKF, us, zs),
    "EKF  quadlib checked calls": lambda us, zs: run_checked(ModelEKF, us, zs),
    "EKF  textbook numpy (Alg. 2)": lambda us, zs: run_textbook(ekf_predict, ekf_update, (), us, zs),
    "UKF  bare filterpy": run_bare_ukf,
    "UKF  quadlib run_filter": lambda us, zs: run_replay(ModelUKF, us, zs),
    "UKF  quadlib checked calls": lambda us, zs: run_checked(ModelUKF, us, zs),
    "UKF  textbook numpy (Alg. 3)": lambda us, zs: run_textbook(ukf_predict, ukf_update, (ALPHA, BETA, KAPPA),
                                                                us, zs),
}


def main() -> None:
    us, zs = make_log()
    best = dict.fromkeys(VARIANTS, np.inf)
    estimates = {}
    for _ in range(REPEATS):  # interleaved, so drifts in machine load hit every variant alike
        for name, fn in VARIANTS.items():
            start = time.perf_counter()
            estimates[name] = fn(us, zs)
            best[name] = min(best[name], time.perf_counter() - start)
    print(f"2D quadrotor, {STEPS} predict+update steps, best of {REPEATS} interleaved repeats")
    print(f"{'variant':<29} | {'µs/step':>8} | {'ratio to bare':>13} | max |x - x_bare|")
    for name, seconds in best.items():
        bare = name[:3] + "  bare filterpy"
        diff = np.max(np.abs(estimates[name] - estimates[bare]))
        print(f"{name:<29} | {1e6 * seconds / STEPS:8.1f} | {seconds / best[bare]:13.2f} | {diff:.1e}")


if __name__ == "__main__":
    main()
