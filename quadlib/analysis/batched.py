"""A linear Kalman filter over many runs at once: states ``(M, n)``, covariances ``(M, n, n)``.

:func:`~quadlib.analysis.run_monte_carlo` replays the same filter over ``M`` simulated flights. For a
:class:`~quadlib.LinearKF` each step is the same few matrix products in every run, so they can be
done for all runs together with ``einsum``: one Python step per time step instead of ``M``. The
arithmetic is filterpy's (predict ``x ← F x + B u``, ``P ← F P Fᵀ + Q``; update with the Joseph
form), and the result equals ``M`` separate :func:`~quadlib.run_filter` runs to rounding
(``tests/analysis/test_batched.py``). What differs between runs — missing samples, samples a gate
rejects — is a per-run mask.

Supported: linear models and sensors (what :class:`~quadlib.LinearKF` accepts), inputs shared by
all runs, sensors with one measurement group when gated, no timed reset and no ``uncorrected``
states. :func:`batch_supported` says whether a filter and its sensors qualify.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from quadlib.filters import LinearKF
from quadlib.model import Sensor
from quadlib.model_filter import group_gates
from quadlib.replay import held_inputs
from quadlib.samples import Measurements, time_resolution

__all__ = ["batch_supported", "run_linear_batch"]


def batch_supported(filt, sensors: Sequence[Sensor], gate_probability: float | None) -> bool:
    """True when :func:`run_linear_batch` gives what :func:`~quadlib.run_filter` would for ``filt``."""
    if type(filt) is not LinearKF:
        return False
    for s in sensors:
        if s.uncorrected or s.residual is not np.subtract or s.dim_c or (
                gate_probability is not None and (len(s.groups) > 1 or s.reset_after_s is not None)):
            return False
        filt._check_sensor_linear(s)  # a nonlinear sensor is refused as LinearKF refuses it
    return True


def run_linear_batch(filt: LinearKF, x0s, t, u, measurements: Sequence[Sequence[Measurements]],
                     gate_probability: float | None = None):
    """Run ``filt``'s model and prior covariance over ``M`` runs at once.

    Parameters
    ----------
    filt : LinearKF
        Supplies the model, ``P0`` and the linearity checks; it is not advanced.
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
    model = filt.model
    t = np.asarray(t, dtype=float)
    x = np.array(x0s, dtype=float)
    M, N, n = x.shape[0], t.size, model.dim_x
    u, _ = held_inputs(model, u, N)
    P = np.broadcast_to(filt._P0, (M, n, n)).copy()
    first = measurements[0]
    grid = time_resolution(t)
    schedule: dict[int, list] = {}
    out_nis, out_rejected = {}, {}
    for i, m in enumerate(first):
        sensor = m.sensor
        tol = max(grid, m.time_resolution_s)
        steps = np.searchsorted(t, m.t - tol, side="left")
        keep = ~np.r_[False, np.diff(m.t) <= tol]  # a repeated timestamp is dropped in every run
        z = np.stack([run[i].z for run in measurements])  # (M, K, k)
        missing = np.stack([run[i].missing for run in measurements])  # (M, K)
        H = np.asarray(sensor.H(x[0]), dtype=float)
        gate = None if gate_probability is None else group_gates(sensor, gate_probability)[0]
        out_nis[sensor.name] = np.full((M, m.t.size), np.nan)
        out_rejected[sensor.name] = np.zeros(M, int)
        for j in np.flatnonzero(keep):
            schedule.setdefault(int(steps[j]), []).append((i, int(j), sensor, H, z[:, j], missing[:, j], gate))
    xs, Ps = np.empty((M, N, n)), np.empty((M, N, n, n))
    eye = np.eye(n)
    for k in range(N):
        if k:
            dt = float(t[k] - t[k - 1])
            uk = u[k - 1]
            F = np.asarray(model.G(x[0], uk, dt), dtype=float)
            Q = filt._process_noise(dt, uk)
            x = x @ F.T
            if model.dim_u:
                x = x + np.asarray(model.B(x[0], uk, dt), dtype=float) @ uk
            P = np.einsum("ij,mjk,lk->mil", F, P, F) + Q
        for _, j, sensor, H, z, missing, gate in schedule.get(k, ()):
            y = np.where(missing[:, None], 0.0, z) - x @ H.T
            PHT = P @ H.T
            S = H @ PHT + sensor.R
            SI = np.linalg.inv(S)
            nis = np.einsum("mi,mij,mj->m", y, SI, y)
            use = ~missing
            if gate is not None:
                rejected = use & (nis > gate)
                out_rejected[sensor.name] += rejected
                use = use & ~rejected
            out_nis[sensor.name][:, j] = np.where(missing, np.nan, nis)
            if use.any():
                K = PHT[use] @ SI[use]
                x[use] = x[use] + np.einsum("mij,mj->mi", K, y[use])
                I_KH = eye - K @ H
                P[use] = I_KH @ P[use] @ np.swapaxes(I_KH, 1, 2) + K @ sensor.R @ np.swapaxes(K, 1, 2)
        xs[:, k], Ps[:, k] = x, P
    return xs, Ps, out_nis, out_rejected
