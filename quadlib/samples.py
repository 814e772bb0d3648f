"""Sensor samples: a raw stream, and a stream bound to the sensor model that explains it.

Simulators and data loaders produce :class:`Samples` — times and values, nothing more. An estimator
pairs them with its own measurement model as :class:`Measurements`, which
:func:`~quadlib.replay.run_filter` consumes. (IMU streams, which drive the prediction instead of
updating it, travel as one :class:`~quadlib.imu.ImuLog`.) Missing samples are rows of NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.model import Sensor
from quadlib.validation import as_finite_array, as_finite_number, as_float_array

__all__ = ["Measurements", "Samples", "stuck_rows", "time_resolution"]


def time_resolution(t) -> float:
    """The precision of the times ``t`` [s]: four units in the last place of the largest, at the
    floating-point type they are stored in (at least 1 ns)."""
    arr = np.asarray(t)
    if arr.dtype.kind != "f" or arr.size == 0 or not np.isfinite(arr).all():
        return 1e-9
    return max(1e-9, 4 * float(np.finfo(arr.dtype).eps) * float(np.max(np.abs(arr))))


def _window(t: np.ndarray, start_s: float, end_s: float, tol: float) -> np.ndarray:
    """(K,) bool: ``start_s <= t <= end_s`` to within ``tol`` [s]."""
    start_s, end_s = as_finite_number("start_s", start_s), as_finite_number("end_s", end_s)
    return (t >= start_s - tol) & (t <= end_s + tol)


def stuck_rows(v, n: int) -> np.ndarray:
    """``(N,)`` bool: the row is present and equal to the ``n − 1`` present rows before it (NaN rows
    skipped): a sensor that froze and repeats its last reading. From the ``n``-th equal reading on."""
    v = np.asarray(v, dtype=float)
    v = v.reshape(len(v), -1)
    present = np.flatnonzero(~np.isnan(v).any(axis=-1))
    stuck = np.zeros(v.shape[0], bool)
    if present.size < n:
        return stuck
    same = np.r_[False, (v[present[1:]] == v[present[:-1]]).all(axis=-1)]
    index = np.arange(present.size)
    run = index - np.maximum.accumulate(np.where(same, 0, index))  # equal readings before this one, in a row
    stuck[present] = run >= n - 1
    return stuck


@dataclass(frozen=True)
class Samples:
    """Samples of one sensor: ``z[j]`` (a row) taken at ``t[j]`` [s]; NaN rows are missing samples.

    ``t`` is finite, 1-D and non-decreasing; ``z`` has one row per time (``(K,)`` or ``(K, k)``),
    finite or NaN.
    """

    t: np.ndarray
    z: np.ndarray

    def __post_init__(self):
        t = as_finite_array("Samples.t", self.t, ndim=1)
        back = np.flatnonzero(np.diff(t) < 0)
        if back.size:
            j = int(back[0]) + 1
            raise ValueError(f"Samples.t: expected non-decreasing times, got t[{j}] = {t[j]:.9g} s before "
                             f"t[{j - 1}] = {t[j - 1]:.9g} s")
        try:
            z = None if isinstance(self.z, (str, bytes)) else np.asarray(self.z, dtype=float)
        except (TypeError, ValueError):
            z = None
        if z is None or z.ndim not in (1, 2) or z.shape[0] != t.shape[0]:
            raise ValueError(f"Samples.z: expected one row per time, shape ({t.shape[0]},) or ({t.shape[0]}, k), "
                             f"got {getattr(z, 'shape', repr(self.z))}")
        if np.isinf(z).any():
            raise ValueError("Samples.z: expected finite values or NaN for missing, got inf")
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "z", z)

    def between(self, start_s: float, end_s: float) -> Samples:
        """The samples taken from ``start_s`` to ``end_s`` [s], both included."""
        keep = _window(self.t, start_s, end_s, time_resolution(self.t))
        return Samples(self.t[keep], self.z[keep])


@dataclass(frozen=True)
class Measurements:
    """Samples of one sensor: ``z[j]`` taken at ``t[j]``; NaN rows are missing samples.

    Parameters
    ----------
    sensor : Sensor
    t : (K,) array_like
        Non-decreasing sample times [s].
    z : (K, k) array_like (or (K,) when k == 1)
        Samples; a row containing NaN marks a missing sample.
    context : (K, c) array_like, optional
        Per-sample context for a sensor with ``context_names``; a row
        containing NaN also marks the sample missing.

    A timestamp that repeats the previous one is a duplicate: :func:`~quadlib.replay.run_filter`
    drops it and counts it. ``time_resolution_s`` is the precision the times were given in
    (float32 times are good to about 1e-7 of their value), the tolerance when they are matched
    to the filter's steps.
    """

    sensor: Sensor
    t: np.ndarray
    z: np.ndarray
    context: np.ndarray | None = None
    time_resolution_s: float = field(init=False, default=1e-9)

    def __post_init__(self):
        if not isinstance(self.sensor, Sensor):
            raise TypeError(f"Measurements.sensor: expected a quadlib Sensor, got {type(self.sensor).__name__}")
        name = self.sensor.name
        object.__setattr__(self, "time_resolution_s", time_resolution(self.t))
        t = as_finite_array(f"Measurements({name!r}).t", self.t, ndim=1)
        back = np.flatnonzero(np.diff(t) < 0)
        if back.size:
            j = int(back[0]) + 1
            raise ValueError(f"Measurements({name!r}).t: expected non-decreasing times (sort the log first), got "
                             f"t[{j}] = {t[j]:.9g} s before t[{j - 1}] = {t[j - 1]:.9g} s")
        z = as_float_array(f"Measurements({name!r}).z", self.z)
        if z.ndim == 1 and self.sensor.dim_z == 1:
            z = z.reshape(-1, 1)
        if z.shape != (t.shape[0], self.sensor.dim_z):
            raise ValueError(
                f"Measurements({name!r}).z: expected shape ({t.shape[0]}, {self.sensor.dim_z}), got {z.shape}"
            )
        if np.any(np.isinf(z)):
            raise ValueError(f"Measurements({name!r}).z: expected finite values or NaN for missing, got inf")
        c = self.sensor.dim_c
        if (self.context is None) != (c == 0):
            raise ValueError(f"Measurements({name!r}).context: expected {'None' if not c else f'shape ({len(t)}, {c})'}"
                             f" for a sensor with context_names {self.sensor.context_names}, got "
                             f"{None if self.context is None else np.shape(self.context)}")
        if c:
            context = as_float_array(f"Measurements({name!r}).context", self.context)
            if context.ndim == 1 and c == 1:
                context = context.reshape(-1, 1)
            if context.shape != (t.shape[0], c) or np.any(np.isinf(context)):
                raise ValueError(f"Measurements({name!r}).context: expected finite values or NaN of shape "
                                 f"({t.shape[0]}, {c}), got shape {context.shape}")
            object.__setattr__(self, "context", context)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "z", z)

    def between(self, start_s: float, end_s: float) -> Measurements:
        """The samples (and their context) taken from ``start_s`` to ``end_s`` [s], both included."""
        keep = _window(self.t, start_s, end_s, self.time_resolution_s)
        context = None if self.context is None else self.context[keep]
        return Measurements(self.sensor, self.t[keep], self.z[keep], context)

    @property
    def missing(self) -> np.ndarray:
        """(K,) bool: the sample (or its context) has a NaN, or it repeats a frozen reading
        (``sensor.stuck_samples``)."""
        bad = np.isnan(self.z).any(axis=1)
        if self.context is not None:
            bad = bad | np.isnan(self.context).any(axis=1)
        if self.sensor.stuck_samples is not None:
            bad = bad | stuck_rows(np.where(bad[:, None], np.nan, self.z), self.sensor.stuck_samples)
        return bad
