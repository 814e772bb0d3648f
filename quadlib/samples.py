"""Sensor samples: a raw stream, and a stream bound to the sensor model that explains it.

Simulators and data loaders produce :class:`Samples` — times and values, nothing more. An estimator
pairs them with its own measurement model as :class:`Measurements`, which
:func:`~quadlib.replay.run_filter` consumes. (IMU streams, which drive the prediction instead of
updating it, travel as one :class:`~quadlib.imu.ImuLog`.) Missing samples are rows of NaN.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from quadlib.model import Sensor
from quadlib.validation import as_finite_array

__all__ = ["Measurements", "Samples"]


class Samples(NamedTuple):
    """Samples of one sensor: ``z[j]`` (a row) taken at ``t[j]`` [s]; NaN rows are missing samples."""

    t: np.ndarray
    z: np.ndarray


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
    """

    sensor: Sensor
    t: np.ndarray
    z: np.ndarray
    context: np.ndarray | None = None

    def __post_init__(self):
        if not isinstance(self.sensor, Sensor):
            raise TypeError(f"Measurements.sensor: expected a quadlib Sensor, got {type(self.sensor).__name__}")
        name = self.sensor.name
        t = as_finite_array(f"Measurements({name!r}).t", self.t, ndim=1)
        if np.any(np.diff(t) < 0):
            raise ValueError(f"Measurements({name!r}).t: expected non-decreasing times, got a decrease")
        z = np.asarray(self.z, dtype=float)
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
            context = np.asarray(self.context, dtype=float)
            if context.ndim == 1 and c == 1:
                context = context.reshape(-1, 1)
            if context.shape != (t.shape[0], c) or np.any(np.isinf(context)):
                raise ValueError(f"Measurements({name!r}).context: expected finite values or NaN of shape "
                                 f"({t.shape[0]}, {c}), got shape {context.shape}")
            object.__setattr__(self, "context", context)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "z", z)

    @property
    def missing(self) -> np.ndarray:
        """(K,) bool: the sample (or its context) has a NaN."""
        bad = np.isnan(self.z).any(axis=1)
        return bad if self.context is None else bad | np.isnan(self.context).any(axis=1)
