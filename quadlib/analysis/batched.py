"""One filter over many runs at once: states ``(M, n)``, covariances ``(M, n, n)``.

:func:`~quadlib.analysis.run_monte_carlo` replays the same filter over ``M`` simulated flights. Each
step is the same few matrix products in every run, so they can be done for all runs together:
one Python step per time step instead of ``M``. The arithmetic is that of the per-run filters:

* :class:`~quadlib.LinearKF`: filterpy's predict ``x ← F x + B u``, ``P ← F P Fᵀ + Q``, and the
  Joseph-form update;
* :class:`~quadlib.ModelEKF`: ``x ← g(x, u, Δt)``, ``P ← G P Gᵀ + Q`` with ``G`` at each run's
  state, and the same update with each run's ``H``;
* :class:`~quadlib.ModelUKF` with its default sigma points: filterpy's unscented predict and update,
  then the covariance symmetrised (and repaired when rounding left it indefinite).

The nonlinear filters need a model and sensors whose functions take a stack of states
(``Model.vectorized``, ``Sensor.vectorized``). The results equal ``M`` separate
:func:`~quadlib.run_filter` runs to rounding (``tests/analysis/test_batched.py``). What differs
between runs — missing samples, samples a gate rejects — is a per-run mask.

Supported: inputs shared by all runs, sensors with one measurement group when gated, no timed
reset, no ``uncorrected`` states, no context, the plain residual and mean; additive models
without ``normalize`` or input-dependent noise. :func:`batch_supported` says whether a filter and
its sensors qualify.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints

from quadlib.filters import LinearKF, ModelEKF, ModelUKF, positive_definite
from quadlib.model import Sensor
from quadlib.model_filter import group_gates
from quadlib.replay import held_inputs, sample_steps
from quadlib.samples import Measurements, time_resolution

__all__ = ["batch_supported", "run_batch"]


def _default_ukf(filt) -> bool:
    """A ModelUKF with its own sigma points and plain means and residuals."""
    points = filt.points_fn
    return (type(points) is MerweScaledSigmaPoints and points.subtract is np.subtract
            and filt.x_mean is None and filt.residual_x is np.subtract and filt.state_add is np.add)


def batch_supported(filt, sensors: Sequence[Sensor], gate_probability: float | None) -> bool:
    """True when :func:`run_batch` gives what :func:`~quadlib.run_filter` would for ``filt``."""
    if type(filt) is LinearKF:
        for s in sensors:
            filt._check_sensor_linear(s)  # a nonlinear sensor is refused as LinearKF refuses it
    elif type(filt) in (ModelEKF, ModelUKF):
        m = filt.model
        if not m.vectorized or m.is_error_state or m.normalize is not None or m.input_noise is not None:
            return False
        if type(filt) is ModelUKF and not _default_ukf(filt):
            return False
        if not all(s.vectorized and s.mean is None for s in sensors):
            return False
    else:
        return False
    return not any(s.uncorrected or s.residual is not np.subtract or s.dim_c or (
        gate_probability is not None and (len(s.groups) > 1 or s.reset_after_s is not None)) for s in sensors)


def _rows(values, M: int, shape: tuple[int, ...]) -> np.ndarray:
    """A vectorized model function's result for ``M`` stacked inputs, as ``(M, *shape)``."""
    return np.asarray(values, dtype=float).reshape((M,) + shape)


def _sigma_points(points, x, P):
    """Van der Merwe's sigma points of every run, ``(M, 2n + 1, n)``: ``x``, ``x + Uₖ``, ``x − Uₖ``
    with the rows ``Uₖ`` of the upper Cholesky factor of ``(λ + n) P``."""
    n = x.shape[1]
    lam = points.alpha**2 * (n + points.kappa) - n
    U = np.swapaxes(np.linalg.cholesky((lam + n) * P), 1, 2)
    return np.concatenate([x[:, None], x[:, None] - (-U), x[:, None] - U], axis=1)


def _positive_definite(P):
    """:func:`quadlib.filters.positive_definite` of every run."""
    P = 0.5 * (P + np.swapaxes(P, 1, 2))
    try:
        np.linalg.cholesky(P)
        return P
    except np.linalg.LinAlgError:
        return np.array([positive_definite(p) for p in P])


def _predict(filt, x, P, uk, dt):
    model, M = filt.model, x.shape[0]
    n = model.dim_x
    Q = filt._process_noise(dt, uk)
    if type(filt) is LinearKF:
        F = np.asarray(model.G(x[0], uk, dt), dtype=float)
        x = x @ F.T
        if model.dim_u:
            x = x + np.asarray(model.B(x[0], uk, dt), dtype=float) @ uk
        return x, np.einsum("ij,mjk,lk->mil", F, P, F) + Q
    if type(filt) is ModelEKF:
        F = _rows(model.G(x, uk, dt), M, (n, n))
        return _rows(model.g(x, uk, dt), M, (n,)), F @ P @ np.swapaxes(F, 1, 2) + Q
    sigmas = _sigma_points(filt.points_fn, x, P)
    moved = _rows(model.g(sigmas.reshape(-1, n), uk, dt), M, sigmas.shape[1:])
    x = np.einsum("s,msi->mi", filt.Wm, moved)
    d = moved - x[:, None]
    return x, np.einsum("msi,s,msj->mij", d, filt.Wc, d) + Q


def _update(filt, sensor, x, P, z):
    """Every run's update with its sample ``z``: the innovation ``y``, ``S``, ``S⁻¹`` and the
    updated ``x`` and ``P``."""
    M, k = x.shape[0], sensor.dim_z
    R = sensor.R
    if type(filt) is ModelUKF:
        n = x.shape[1]
        sigmas = _sigma_points(filt.points_fn, x, P)
        measured = _rows(sensor.h(sigmas.reshape(-1, n)), M, (sigmas.shape[1], k))
        z_mean = np.einsum("s,msj->mj", filt.Wm, measured)
        dz, dx = measured - z_mean[:, None], sigmas - x[:, None]
        S = np.einsum("msi,s,msj->mij", dz, filt.Wc, dz) + R
        SI = np.linalg.inv(S)
        K = np.einsum("msi,s,msj->mij", dx, filt.Wc, dz) @ SI
        y = z - z_mean
        x_new = x + np.einsum("mij,mj->mi", K, y)
        return y, S, SI, x_new, _positive_definite(P - K @ S @ np.swapaxes(K, 1, 2))
    if type(filt) is LinearKF:
        H = np.broadcast_to(np.asarray(sensor.H(x[0]), dtype=float), (M, k, x.shape[1]))
        y = z - x @ H[0].T
    else:
        H = _rows(sensor.H(x), M, (k, x.shape[1]))
        y = z - _rows(sensor.h(x), M, (k,))
    PHT = P @ np.swapaxes(H, 1, 2)
    S = H @ PHT + R
    SI = 1.0 / S if k == 1 else np.linalg.inv(S)
    K = PHT @ SI
    I_KH = np.eye(x.shape[1]) - K @ H
    x_new = x + np.einsum("mij,mj->mi", K, y)
    return y, S, SI, x_new, I_KH @ P @ np.swapaxes(I_KH, 1, 2) + K @ R @ np.swapaxes(K, 1, 2)


def run_batch(filt, x0s, t, u, measurements: Sequence[Sequence[Measurements]],
              gate_probability: float | None = None):
    """Run ``filt``'s model and prior covariance over ``M`` runs at once (module documentation).

    Parameters
    ----------
    filt : LinearKF, ModelEKF or ModelUKF
        Supplies the model, ``P0``, the sigma points and the checks; it is not advanced.
        :func:`batch_supported` must be True for it and the sensors.
    x0s : (M, n) array_like
        Each run's initial mean.
    t : (N,) array_like
        The common time grid [s]; ``u`` (N, m) or None the common inputs.
    measurements : sequence of M sequences of Measurements
        Each run's samples, the same sensors and sample times in every run (values and NaNs may differ).
    gate_probability : float, optional

    Returns
    -------
    x : (M, N, n), P : (M, N, n, n), nis : dict of sensor name -> (M, K), rejected : dict of name -> (M,)
    """
    if not batch_supported(filt, [m.sensor for m in measurements[0]], gate_probability):
        raise ValueError(f"filt: expected a filter and sensors run_batch supports (batch_supported), got "
                         f"{type(filt).__name__} of {filt.model.name!r}")
    model = filt.model
    t = np.asarray(t, dtype=float)
    x = np.array(x0s, dtype=float)
    M, N, n = x.shape[0], t.size, model.dim_x
    u, _ = held_inputs(model, u, N)
    P = np.broadcast_to(filt._P0, (M, n, n)).copy()
    grid = time_resolution(t)
    schedule: dict[int, list] = {}
    out_nis, out_rejected = {}, {}
    for i, m in enumerate(measurements[0]):
        sensor = m.sensor
        steps, _, repeated = sample_steps(t, grid, m)  # a repeated timestamp is dropped in every run
        z = np.stack([run[i].z for run in measurements])  # (M, K, k)
        missing = np.stack([run[i].missing for run in measurements])  # (M, K)
        gate = None if gate_probability is None else group_gates(sensor, gate_probability)[0]
        out_nis[sensor.name] = np.full((M, m.t.size), np.nan)
        out_rejected[sensor.name] = np.zeros(M, int)
        for j in np.flatnonzero(~repeated):
            schedule.setdefault(int(steps[j]), []).append((j, sensor, z[:, j], missing[:, j], gate))
    xs, Ps = np.empty((M, N, n)), np.empty((M, N, n, n))
    for k in range(N):
        if k:
            x, P = _predict(filt, x, P, u[k - 1], float(t[k] - t[k - 1]))
        for j, sensor, z, missing, gate in schedule.get(k, ()):
            y, _, SI, x_new, P_new = _update(filt, sensor, x, P, np.where(missing[:, None], 0.0, z))
            nis = np.einsum("mi,mij,mj->m", y, SI, y)
            use = ~missing
            if gate is not None:
                rejected = use & (nis > gate)
                out_rejected[sensor.name] += rejected
                use = use & ~rejected
            out_nis[sensor.name][:, j] = np.where(missing, np.nan, nis)
            x[use], P[use] = x_new[use], P_new[use]
        xs[:, k], Ps[:, k] = x, P
    return xs, Ps, out_nis, out_rejected
