"""Replay a multi-rate sensor log through a filter.

The timeline: inputs ``u[k]`` are given at times ``t[k]`` and hold over
``[t[k], t[k+1])``. The filter starts at ``t[0]``; at each later ``t[k]`` it
predicts over ``t[k] - t[k-1]`` with ``u[k-1]``, then applies every sensor
sample whose timestamp falls in ``(t[k-1], t[k]]`` (samples at exactly
``t[0]`` are applied before the first predict). A sample is thus applied at
the first prediction time at or after its timestamp — at most one input
period late; simulate sensors on the input grid to avoid even that.

A missing sample is a row of NaN in ``z``: it is skipped and counted, and the
filter keeps predicting (a dropout). With ``gate_probability`` set, samples
whose NIS exceeds the χ² quantile are rejected and counted (outliers).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.model_filter import ModelFilter, gate_threshold
from quadlib.samples import Measurements
from quadlib.validation import as_probability, as_times

__all__ = ["FilterRun", "SensorTrace", "run_filter"]

_TIME_TOL_S = 1e-9


@dataclass(frozen=True)
class SensorTrace:
    """What the filter did with each sample of one sensor.

    Attributes
    ----------
    t : (K,) sample times [s]
    innovation : (K, k) innovations; NaN where the sample was missing
    S : (K, k, k) innovation covariances; NaN where missing
    nis : (K,) normalised innovation squared; NaN where missing
    used : (K,) bool, the sample updated the state
    rejected : (K,) bool, the gate rejected the sample
    missing : (K,) bool, the sample was NaN
    """

    t: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    nis: np.ndarray
    used: np.ndarray
    rejected: np.ndarray
    missing: np.ndarray


@dataclass(frozen=True)
class FilterRun:
    """Result of :func:`run_filter`.

    Attributes
    ----------
    t : (N,) times [s]
    x : (N, n) posterior means at ``t``
    P : (N, p, p) posterior covariances at ``t`` (over the error state for an error-state model)
    sensors : dict of sensor name -> SensorTrace
    """

    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    sensors: dict

    @property
    def sigma(self) -> np.ndarray:
        """(N, p) standard deviations, the square roots of the diagonal of ``P``."""
        return np.sqrt(np.clip(np.diagonal(self.P, axis1=1, axis2=2), 0.0, None))


def run_filter(filt, t, u, measurements, gate_probability: float | None = None) -> FilterRun:
    """Run ``filt`` over a log: predict at every input time, update at every sample.

    Parameters
    ----------
    filt : LinearKF, ModelEKF or ModelUKF
        Initialised filter; it is advanced in place.
    t : (N,) array_like
        Strictly increasing input times [s]; ``t[0]`` is the time of the initial state.
    u : (N, m) array_like, or None when the model has no input
        Inputs; ``u[k]`` holds over ``[t[k], t[k+1])`` (the last row is unused).
    measurements : sequence of Measurements
        One entry per sensor, applied in the given order when they share a step.
    gate_probability : float in (0, 1), optional
        NIS gate for every sensor (see ``update_sensor``).

    Returns
    -------
    FilterRun
    """
    if not isinstance(filt, ModelFilter):
        raise TypeError(f"filt: expected a LinearKF, ModelEKF or ModelUKF, got {type(filt).__name__}")
    t = as_times("t", t)
    N = t.shape[0]
    model = filt.model
    u = model.check_inputs(u, N)
    if gate_probability is not None:
        gate_probability = as_probability("gate_probability", gate_probability)
    measurements = list(measurements)
    for i, m in enumerate(measurements):
        if not isinstance(m, Measurements):
            raise TypeError(f"measurements[{i}]: expected Measurements, got {type(m).__name__}")
        filt.check_sensor(m.sensor, f"measurements[{i}].sensor")
        if m.t.size and (m.t[0] < t[0] - _TIME_TOL_S or m.t[-1] > t[-1] + _TIME_TOL_S):
            raise ValueError(
                f"measurements[{i}] ({m.sensor.name!r}).t: expected times within "
                f"[{t[0]:.6g}, {t[-1]:.6g}] s, got [{m.t[0]:.6g}, {m.t[-1]:.6g}] s"
            )
    names = [m.sensor.name for m in measurements]
    if len(set(names)) != len(names):
        raise ValueError(f"measurements: expected one entry per sensor name, got {names}")

    # Events (step index, sensor index, sample index), sorted by step then sensor order.
    steps, sensor_idx, sample_idx = [], [], []
    for i, m in enumerate(measurements):
        steps.append(np.searchsorted(t, m.t - _TIME_TOL_S, side="left"))
        sensor_idx.append(np.full(m.t.shape[0], i))
        sample_idx.append(np.arange(m.t.shape[0]))
    if measurements:
        steps, sensor_idx, sample_idx = (np.concatenate(a) for a in (steps, sensor_idx, sample_idx))
        order = np.lexsort((sample_idx, sensor_idx, steps))
        events = list(zip(steps[order].tolist(), sensor_idx[order].tolist(), sample_idx[order].tolist(),
                          strict=True))
    else:
        events = []

    missing = [m.missing for m in measurements]
    gates = [None if gate_probability is None else gate_threshold(m.sensor.dim_z, gate_probability)
             for m in measurements]
    schedule: dict[int, list] = {}  # step -> the updates applied after its predict
    for k, i, j in events:
        if not missing[i][j]:
            m = measurements[i]
            c = None if m.context is None else m.context[j]
            schedule.setdefault(k, []).append((i, j, m.sensor, m.z[j], gates[i], c))

    # Everything was validated above, so the loop uses the filter's unchecked steps
    # and the whole trajectory is checked for non-finite values once at the end.
    xs, Ps = np.empty((N, model.dim_x)), np.empty((N, model.dim_P, model.dim_P))
    inputs, dts = list(u), np.diff(t).tolist()
    done = []  # (sensor index, sample index, Innovation)
    for k in range(N):
        if k:
            filt.predict_unchecked(inputs[k - 1], dts[k - 1])
        for i, j, sensor, z, gate, c in schedule.get(k, ()):
            done.append((i, j, filt.update_unchecked(sensor, z, gate, c)))
        xs[k] = filt.state_view()  # copied into xs
        Ps[k] = filt.P

    traces = []
    for i, m in enumerate(measurements):
        K, k = m.z.shape
        traces.append(dict(innovation=np.full((K, k), np.nan), S=np.full((K, k, k), np.nan),
                           nis=np.full(K, np.nan), used=np.zeros(K, bool), rejected=np.zeros(K, bool),
                           missing=missing[i]))
    for i, j, inn in done:
        tr = traces[i]
        tr["innovation"][j], tr["S"][j], tr["nis"][j] = inn.y, inn.S, inn.nis
        tr["used"][j], tr["rejected"][j] = inn.accepted, not inn.accepted
    bad = ~np.isfinite(xs).all(axis=1) | ~np.isfinite(Ps).all(axis=(1, 2))
    if bad.any():
        k = int(np.argmax(bad))
        raise FloatingPointError(
            f"run_filter: the state or covariance became non-finite at t[{k}] = {t[k]:.6g} s; "
            "check the model, Q, R and the inputs"
        )
    sensors = {m.sensor.name: SensorTrace(t=m.t, **tr) for m, tr in zip(measurements, traces, strict=True)}
    return FilterRun(t=t, x=xs, P=Ps, sensors=sensors)
