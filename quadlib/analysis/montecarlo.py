"""Monte Carlo: exact answers for one nonlinear step, and filters over many simulated runs.

* :func:`propagate_samples` and :func:`importance_posterior` give the exact moments of a Gaussian
  through a nonlinear function and after one update, up to sampling noise — the yardstick for
  the EKF's linearisation and the UKF's unscented transform (chapters 06–07).
* :func:`run_monte_carlo` runs several filters on the same simulated flights and collects
  errors, σ, NEES and NIS for consistency tables (chapters 08–09); a linear Kalman filter runs over
  all flights at once (:mod:`~quadlib.analysis.batched`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from quadlib.analysis.batched import batch_supported, run_batch
from quadlib.analysis.metrics import nees
from quadlib.model import Model, Sensor
from quadlib.progress import progress
from quadlib.replay import run_filter
from quadlib.samples import Measurements
from quadlib.sim.simulate import sample_sensor, simulate_model
from quadlib.validation import as_bool, as_count, as_covariance, as_instance, as_probability, as_rng, as_vector

__all__ = ["Moments", "MonteCarloRuns", "importance_posterior", "propagate_samples", "run_monte_carlo"]


class Moments(NamedTuple):
    """Mean ``(k,)`` and covariance ``(k, k)`` of a sample set."""

    mean: np.ndarray
    cov: np.ndarray


def _samples(mu, P, n_samples: int, rng) -> np.ndarray:
    mu = as_vector("mu", mu)
    P = as_covariance(f"P (for mu of size {mu.size})", P, mu.size)
    n_samples = as_count("n_samples", n_samples, low=2)
    return as_rng(rng).multivariate_normal(mu, P, size=n_samples, method="eigh")


def propagate_samples(f, mu, P, n_samples: int, rng) -> tuple[Moments, np.ndarray]:
    """Push ``n_samples`` draws of ``N(mu, P)`` through ``f`` (vectorised over rows).

    Returns the sample mean and covariance of ``f(x)`` and the ``(n_samples, k)`` outputs.
    ``f`` must accept an ``(n_samples, n)`` array and return ``(n_samples,)`` or ``(n_samples, k)``.
    """
    if not callable(f):
        raise TypeError(f"f: expected a callable, got {f!r}")
    y = np.asarray(f(_samples(mu, P, n_samples, rng)), dtype=float)
    y = y.reshape(n_samples, -1)
    return Moments(y.mean(axis=0), np.atleast_2d(np.cov(y, rowvar=False))), y


def importance_posterior(sensor: Sensor, mu, P, z, n_samples: int, rng) -> Moments:
    """Bayes posterior mean and covariance for prior ``N(mu, P)`` and one sample ``z`` of ``sensor``.

    Prior draws are weighted by the Gaussian likelihood ``N(z; h(x), R)``; ``sensor.h`` must
    accept an ``(n_samples, n)`` array and return ``(n_samples, k)`` (or ``(n_samples,)`` for k = 1).
    """
    sensor = as_instance("sensor", sensor, Sensor)
    x = _samples(mu, P, n_samples, rng)
    z = sensor.check_measurement(z)
    r = z - np.asarray(sensor.h(x), dtype=float).reshape(n_samples, sensor.dim_z)
    log_w = -0.5 * np.einsum("ij,jk,ik->i", r, np.linalg.inv(sensor.R), r)
    w = np.exp(log_w - log_w.max())
    w /= w.sum()
    mean = w @ x
    d = x - mean
    return Moments(mean, d.T @ (w[:, None] * d))


@dataclass(frozen=True)
class MonteCarloRuns:
    """One filter over ``M`` simulated runs of ``N`` steps (``n`` states).

    Attributes
    ----------
    t : (N,) times [s]
    truth : (M, N, n) the simulated true states (the same array for every filter of one call)
    errors : (M, N, n) estimate minus truth
    sigma : (M, N, n) the filter's standard deviations
    nees : (M, N) normalised estimation error squared
    nis : dict of sensor name -> (M, K) NIS per sample (NaN where missing)
    rejected : dict of sensor name -> (M,) samples rejected by the gate in each run
    """

    t: np.ndarray
    truth: np.ndarray
    errors: np.ndarray
    sigma: np.ndarray
    nees: np.ndarray
    nis: dict
    rejected: dict

    @property
    def n_runs(self) -> int:
        """Number of runs ``M``."""
        return self.errors.shape[0]


def run_monte_carlo(filters: Mapping[str, Callable], model: Model, sensors: Sequence[Sensor], x0, P0, t, u,
                    n_runs: int, rng, *, assumed_sensors: Mapping[str, Sequence[Sensor]] | None = None,
                    corrupt: Callable | None = None, gate_probability: float | None = None,
                    batched: bool = True, progress_label: str | None = None) -> dict[str, MonteCarloRuns]:
    """Run every filter on the same ``n_runs`` simulated flights.

    Each run draws its true initial state from ``N(x0, P0)`` — the prior the filters start
    from — simulates ``model`` with process noise, samples every sensor at its ``rate_hz``,
    optionally corrupts the samples, and replays them through each filter.

    Parameters
    ----------
    filters : mapping of name -> callable ``(x0, P0) -> filter``
        Factories for LinearKF / ModelEKF / ModelUKF instances.
    model : Model
        The truth model (the filters may use other, e.g. mis-tuned, models).
    sensors : sequence of Sensor
        Truth sensors, sampled at their ``rate_hz`` (every step when it is None).
    x0 : (n,) array_like
    P0 : (n, n) array_like
    t : (N,) array_like
        Time grid [s].
    u : (N, m) array_like or None
        Inputs, the same in every run.
    n_runs : int
    rng : numpy.random.Generator
    assumed_sensors : mapping of filter name -> sequence of Sensor, optional
        The sensor models a filter updates with, one per truth sensor and in the same order
        (for example with a mis-tuned ``R``); filters not named use the truth sensors.
    corrupt : callable ``(list of Measurements, rng) -> list of Measurements``, optional
        Applied to each run's samples (dropouts, outliers) before the filters see them.
    gate_probability : float, optional
        NIS gate passed to :func:`~quadlib.replay.run_filter`.
    batched : bool
        Run the filter over all runs at once where :func:`~quadlib.analysis.batched.batch_supported`
        allows (a :class:`~quadlib.LinearKF`, or an EKF or UKF of a vectorized model:
        :mod:`~quadlib.analysis.batched`; the same numbers, many times faster); False replays every
        run on its own.
    progress_label : str, optional
        Show progress bars (:func:`~quadlib.progress.progress`) named after it.

    Returns
    -------
    dict of name -> MonteCarloRuns
    """
    model, rng = as_instance("model", model, Model), as_rng(rng)
    x0 = model.check_state(x0, "x0")
    P0 = as_covariance("P0", P0, model.dim_x)
    n_runs = as_count("n_runs", n_runs)
    if not isinstance(filters, Mapping) or not filters or not all(callable(f) for f in filters.values()):
        raise TypeError(f"filters: expected a non-empty mapping of name -> factory(x0, P0), got {filters!r:.80}")
    if isinstance(sensors, (str, bytes)) or not all(isinstance(s, Sensor) for s in sensors):
        raise TypeError(f"sensors: expected a sequence of Sensor, got {sensors!r:.80}")
    if gate_probability is not None:
        gate_probability = as_probability("gate_probability", gate_probability)
    batched = as_bool("batched", batched)
    if progress_label is not None and not (isinstance(progress_label, str) and progress_label):
        raise TypeError(f"progress_label: expected a non-empty str or None, got {progress_label!r}")
    assumed_sensors = dict(assumed_sensors or {})
    for name, assumed in assumed_sensors.items():
        if name not in filters or len(assumed) != len(sensors):
            raise ValueError(f"assumed_sensors[{name!r}]: expected {len(sensors)} sensors for a filter in "
                             f"filters, got {len(assumed)}")
    def bar(items, what):
        return items if progress_label is None else progress(items, f"{progress_label}: {what}")

    truths, runs_samples = [], []
    for _ in bar(range(n_runs), "simulating"):
        truth = simulate_model(model, rng.multivariate_normal(x0, P0, method="eigh"), t, u, rng)
        truths.append(truth)
        samples = [sample_sensor(s, t, truth, rng) for s in sensors]
        if corrupt is not None:
            samples = list(corrupt(samples, rng))
            if not all(isinstance(m, Measurements) for m in samples):
                raise TypeError("corrupt: expected it to return a list of Measurements")
        runs_samples.append(samples)
    t, truths = np.asarray(t, dtype=float), np.array(truths)
    results = {}
    for name, make in filters.items():
        seen_runs = runs_samples
        if name in assumed_sensors:
            seen_runs = [[Measurements(s, m.t, m.z) for s, m in zip(assumed_sensors[name], samples, strict=True)]
                         for samples in runs_samples]
        first = make(x0, P0)
        if batched and batch_supported(first, [m.sensor for m in seen_runs[0]], gate_probability):
            x, P, nis, rejected = run_batch(first, np.broadcast_to(x0, (n_runs, len(x0))), t, u,
                                            seen_runs, gate_probability)
        else:
            runs = [run_filter(first if i == 0 else make(x0, P0), t, u, seen, gate_probability=gate_probability)
                    for i, seen in bar(list(enumerate(seen_runs)), f"filtering ({name})")]
            x, P = np.array([r.x for r in runs]), np.array([r.P for r in runs])
            nis = {key: np.array([r.sensors[key].nis for r in runs]) for key in runs[0].sensors}
            rejected = {key: np.array([int(r.sensors[key].rejected.sum()) for r in runs]) for key in runs[0].sensors}
        errors = x - truths
        results[name] = MonteCarloRuns(t=t, truth=truths, errors=errors,
                                       sigma=np.sqrt(np.clip(np.diagonal(P, axis1=2, axis2=3), 0.0, None)),
                                       nees=np.array([nees(e, p) for e, p in zip(errors, P, strict=True)]),
                                       nis=nis, rejected=rejected)
    return results
