"""Chapter 9's 2D quadrotor flown closed loop: hold a distance to the wall on the filter's estimate.

The truth steps the model of :func:`~quadlib.quad.quad2d_model` with its process noise, the
rangefinder samples it, the filter (EKF or UKF) predicts with the commanded roll and updates with
each range, and a PD law on the *estimate* commands the next roll:

.. math:: a = k_p\\,(y^* - \\hat y) - k_d\\,\\hat{\\dot y}, \\qquad
          \\varphi_{cmd} = \\arctan(a / g_0), \\ |\\varphi_{cmd}| \\le \\varphi_{max}

(the model's lateral acceleration is ``g₀ tan φ``, so this roll asks for exactly ``a``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.constants import G0
from quadlib.model import Model, Sensor
from quadlib.model_filter import ModelFilter
from quadlib.sim.simulate import gaussian_factor
from quadlib.stepper import FilterStepper, Sample
from quadlib.validation import as_count, as_finite_number, as_instance, as_positive, as_rng, as_times

__all__ = ["PlanarRun", "hold_distance"]


@dataclass(frozen=True)
class PlanarRun:
    """A closed-loop 2D flight: ``t`` (N,), true states ``truth`` (N, 3), the filter's ``x`` and
    ``sigma`` (N, 3), the commanded roll ``roll_cmd`` (N,) [rad], and the ``stepper``
    (:class:`~quadlib.stepper.FilterStepper`) that stepped the filter."""

    t: np.ndarray
    truth: np.ndarray
    x: np.ndarray
    sigma: np.ndarray
    roll_cmd: np.ndarray
    stepper: FilterStepper | None = field(default=None, repr=False, compare=False)


def hold_distance(model: Model, sensor: Sensor, filt: ModelFilter, t, x0, target_y_m: float, rng, *,
                  sample_every: int = 5, k_p: float = 1.5, k_d: float = 2.0,
                  max_roll_rad: float = float(np.radians(15.0))) -> PlanarRun:
    """Fly ``t`` closed loop from the true state ``x0``, steering the estimate's ``y`` to ``target_y_m``.

    ``filt`` is initialised by the caller (its prior need not be the truth); the rangefinder is read
    every ``sample_every`` steps. Gains ``k_p`` [1/s²] and ``k_d`` [1/s].
    """
    model, sensor = as_instance("model", model, Model), as_instance("sensor", sensor, Sensor)
    filt = as_instance("filt", filt, ModelFilter)
    t = as_times("t", t)
    truth = np.empty((t.size, model.dim_x))
    truth[0] = model.check_state(x0, "x0")
    target = as_finite_number("target_y_m", target_y_m)
    rng = as_rng(rng)
    sample_every = as_count("sample_every", sample_every)
    k_p, k_d, max_roll = (as_positive(n, v) for n, v in (("k_p", k_p), ("k_d", k_d), ("max_roll_rad", max_roll_rad)))
    xs, sigmas, roll_cmd = np.empty_like(truth), np.empty_like(truth), np.empty(t.size)
    q_factors, r_factor = {}, gaussian_factor(sensor.R).T  # draws as rng.multivariate_normal(..., method="eigh")
    stepper = FilterStepper(filt, [sensor])
    for k in range(t.size):
        u = None
        if k:
            dt = float(t[k] - t[k - 1])
            u = np.array([roll_cmd[k - 1]])
            if dt not in q_factors:
                q_factors[dt] = gaussian_factor(model.Q(dt)).T
            truth[k] = model.g(truth[k - 1], u, dt) + (rng.standard_normal((1, model.dim_x)) @ q_factors[dt])[0]
        samples = []
        if k % sample_every == 0:
            z = sensor.h(truth[k]) + (rng.standard_normal((1, sensor.dim_z)) @ r_factor)[0]
            samples = [Sample(sensor.name, t[k], z)]
        est, P = stepper.step(t[k], u, samples)
        xs[k], sigmas[k] = est, np.sqrt(np.diag(P))
        accel = k_p * (target - est[2]) - k_d * est[1]
        roll_cmd[k] = float(np.clip(np.arctan(accel / G0), -max_roll, max_roll))
    return PlanarRun(t=t, truth=truth, x=xs, sigma=sigmas, roll_cmd=roll_cmd, stepper=stepper)
