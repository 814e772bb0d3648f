"""Generic simulation of a :class:`Model` and sampling of a :class:`Sensor`.

Every stochastic function takes an ``rng`` (``numpy.random.Generator``).
"""

from __future__ import annotations

import warnings

import numpy as np

from quadlib.model import Model, Sensor
from quadlib.samples import Measurements
from quadlib.validation import (
    as_bool,
    as_finite_array,
    as_finite_number,
    as_instance,
    as_positive,
    as_probability,
    as_rng,
    as_times,
)

__all__ = ["gaussian_factor", "sample_sensor", "simulate_model", "with_dropouts", "with_outliers"]


def gaussian_factor(cov) -> np.ndarray:
    """The factor ``F`` (``F Fᵀ = cov``) that ``rng.multivariate_normal(mean, cov, method="eigh")``
    builds: ``mean + (rng.standard_normal((1, n)) @ F.T)[0]`` is then the same draw, bit for bit,
    without an eigendecomposition per sample. Warns as numpy does when ``cov`` is not positive
    semidefinite."""
    cov = as_finite_array("cov", cov, ndim=2)
    if cov.shape[0] != cov.shape[1]:
        raise ValueError(f"cov: expected a square matrix, got shape {cov.shape}")
    s, u = np.linalg.eigh(cov)
    if np.any(s < -1e-8):  # numpy's check, with its default tolerance
        warnings.warn("covariance is not symmetric positive-semidefinite.", RuntimeWarning, stacklevel=2)
    return u * np.sqrt(abs(s))


def simulate_model(model: Model, x0, t, u, rng, process_noise: bool = True) -> np.ndarray:
    """Truth trajectory ``x[k] = g(x[k-1], u[k-1], dt) + w``, ``w ~ N(0, Q(dt))``.

    Parameters
    ----------
    model : Model
    x0 : (n,) initial state
    t : (N,) strictly increasing times [s]
    u : (N, m) inputs (``u[k]`` holds over ``[t[k], t[k+1])``), or None when m == 0
    rng : numpy.random.Generator
    process_noise : bool
        Add the model's process noise (False gives the noise-free trajectory).

    Returns
    -------
    (N, n) ndarray
    """
    model, rng = as_instance("model", model, Model), as_rng(rng)
    process_noise = as_bool("process_noise", process_noise)
    t = as_times("t", t)
    N = t.shape[0]
    u = model.check_inputs(u, N)
    x = np.empty((N, model.dim_x))
    x[0] = model.check_state(x0, "x0")
    # One draw per step, as rng.multivariate_normal(0, Q(dt), method="eigh") would make it, with
    # the factor of Q(dt) computed once per distinct step length.
    normals = rng.standard_normal((N - 1, model.dim_x)) if process_noise else None
    factors = {}
    for k in range(1, N):
        dt = t[k] - t[k - 1]
        x[k] = model.g(x[k - 1], u[k - 1], dt)
        if process_noise:
            if dt not in factors:
                factors[dt] = gaussian_factor(model.Q(dt)).T
            x[k] += (normals[k - 1:k] @ factors[dt])[0]
    return x


def sample_sensor(sensor: Sensor, t, x, rng, rate_hz: float | None = None) -> Measurements:
    """Noisy samples ``z = h(x) + v``, ``v ~ N(0, R)``, of a truth trajectory.

    Parameters
    ----------
    sensor : Sensor
    t : (N,) truth times [s]
    x : (N, n) truth states
    rng : numpy.random.Generator
    rate_hz : float, optional
        Sample rate; defaults to ``sensor.rate_hz``, or every truth step when
        neither is set. Samples are taken at the truth times nearest to
        multiples of the period, starting at ``t[0]``.

    Returns
    -------
    Measurements
    """
    sensor, rng = as_instance("sensor", sensor, Sensor), as_rng(rng)
    t = as_times("t", t)
    x = as_finite_array("x", x, ndim=2)
    if x.shape[0] != t.shape[0]:
        raise ValueError(f"x: expected {t.shape[0]} rows to match t, got shape {x.shape}")
    rate = rate_hz if rate_hz is not None else sensor.rate_hz
    if rate is None:
        idx = np.arange(t.shape[0])
    else:
        period = 1.0 / as_positive("rate_hz", rate)
        wanted = np.arange(t[0], t[-1] + 1e-9, period)
        idx = np.unique(np.clip(np.searchsorted(t, wanted - 1e-9), 0, t.shape[0] - 1))
    clean = np.array([sensor.h(xi) for xi in x[idx]]).reshape(idx.size, sensor.dim_z)
    noise = rng.multivariate_normal(np.zeros(sensor.dim_z), sensor.R, size=idx.size, method="eigh")
    return Measurements(sensor, t[idx], clean + noise)


def with_dropouts(measurements: Measurements, rng, probability: float) -> Measurements:
    """Copy of ``measurements`` with each sample independently missing (NaN) with ``probability``."""
    measurements, rng = as_instance("measurements", measurements, Measurements), as_rng(rng)
    p = as_probability("probability", probability, open_interval=False)
    z = measurements.z.copy()
    z[rng.random(z.shape[0]) < p] = np.nan
    return Measurements(measurements.sensor, measurements.t, z)


def with_outage(measurements: Measurements, start_s: float, end_s: float) -> Measurements:
    """Copy of ``measurements`` with every sample in ``[start_s, end_s)`` missing (NaN): a sensor
    that stops reporting for a while."""
    measurements = as_instance("measurements", measurements, Measurements)
    start_s = as_finite_number("start_s", start_s)
    end_s = as_finite_number("end_s", end_s)
    if end_s <= start_s:
        raise ValueError(f"end_s: expected a time after start_s = {start_s:g} s, got {end_s!r}")
    z = measurements.z.copy()
    z[(measurements.t >= start_s) & (measurements.t < end_s)] = np.nan
    return Measurements(measurements.sensor, measurements.t, z)


def with_outliers(measurements: Measurements, rng, probability: float,
                  noise_scale: float = 10.0) -> tuple[Measurements, np.ndarray]:
    """Copy of ``measurements`` where each sample is, with ``probability``, an outlier.

    An outlier's noise has ``noise_scale`` times the sensor's standard deviation: extra noise
    ``N(0, (noise_scale² - 1) R)`` is added to the sample (a 10× noise spike by default).
    Missing samples stay missing.

    Returns
    -------
    (Measurements, (K,) bool ndarray)
        The corrupted samples and which of them are outliers.
    """
    measurements, rng = as_instance("measurements", measurements, Measurements), as_rng(rng)
    p = as_probability("probability", probability, open_interval=False)
    scale = as_positive("noise_scale", noise_scale)
    if scale < 1:
        raise ValueError(f"noise_scale: expected >= 1, got {scale}")
    z = measurements.z.copy()
    K, k = z.shape
    outlier = (rng.random(K) < p) & ~np.isnan(z).any(axis=1)
    L = np.linalg.cholesky(measurements.sensor.R)
    z[outlier] += np.sqrt(scale**2 - 1.0) * rng.standard_normal((int(outlier.sum()), k)) @ L.T
    return Measurements(measurements.sensor, measurements.t, z), outlier
