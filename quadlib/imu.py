"""IMU logs and IMU noise: one container and one noise description for every simulator and estimator.

:class:`ImuLog` holds what a strapdown IMU reports on one time grid — gyro, accelerometer and,
where there is one, a magnetometer and an airspeed sensor — in the project's conventions: body
frame FRD, gyro in rad/s, accelerometer as specific force in m/s² (about ``(0, 0, −g₀)`` level
and at rest). A sensor that has no sample at a time has a row of NaN there (a lower rate, a
dropout). Simulators return it, the estimators' one-call entry points take it, and the loaders of
real logs return it too.

:class:`ImuNoise` names every IMU error once, each field with its unit. Simulators draw from it;
estimators derive their process and measurement noise from it. A scenario that needs more (GPS,
airspeed, the Earth's field) extends it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.constants import SATURATED
from quadlib.engine.kernel import Kernel
from quadlib.kernels.attitude import gyro_input_noise
from quadlib.validation import as_float_array, as_positive, as_times, check_fields

__all__ = ["ImuLog", "ImuNoise", "as_imu_stream", "gyro_with_gaps", "rates_to_interval_start", "untrusted_gyro_noise",
           "saturated_step_variance"]


@dataclass(frozen=True)
class ImuNoise:
    """IMU errors per sample (at the IMU's own rate).

    Parameters
    ----------
    gyro_sigma_rad_s : float
        White noise of one gyro sample, per axis [rad/s].
    gyro_bias_rad_s : (3,) tuple
        Gyro bias at the start [rad/s] (simulators draw it; estimators do not know it).
    gyro_bias_walk_rad_s_sqrt_s : float
        Random walk of the gyro bias [rad/s/√s]: after ``T`` seconds its σ is this times √T.
    accel_sigma_m_s2 : float or (3,) tuple
        White noise of one accelerometer sample [m/s²], one value or one per axis.
    mag_sigma : float
        White noise of one magnetometer sample, per axis, in the unit of the field the
        magnetometer reports (gauss, µT, or 1 for a unit vector).
    gyro_range_rad_s : float or None
        The gyro's full scale [rad/s] (2000 °/s = 34.9 rad/s is common): simulators clip each
        axis at it, estimators treat a sample at it as saturated
        (:func:`saturated_step_variance`). None: no limit.
    """

    gyro_sigma_rad_s: float = 0.005
    gyro_bias_rad_s: tuple = (0.0, 0.0, 0.0)
    gyro_bias_walk_rad_s_sqrt_s: float = 0.0
    accel_sigma_m_s2: float | tuple = 0.15
    mag_sigma: float = 0.01
    gyro_range_rad_s: float | None = None

    FIELDS = {"gyro_sigma_rad_s": "nonnegative", "gyro_bias_rad_s": "vector3",
              "gyro_bias_walk_rad_s_sqrt_s": "nonnegative", "accel_sigma_m_s2": "nonnegative or 3",
              "mag_sigma": "nonnegative", "gyro_range_rad_s": "optional positive"}  # a subclass extends it

    def __post_init__(self):
        check_fields(self, self.FIELDS)



def saturated_step_variance(gyro, dt: float, gyro_range_rad_s: float | None) -> float | None:
    """Variance per axis [rad²] of the unknown turn in a gyro step whose sample is saturated.

    A clipped axis says only that the rate is at least the full scale; the turn beyond it over
    ``dt`` is unknown. It is taken as up to the full scale again, a standard deviation of
    ``range · Δt`` per step, so a long saturation leaves the attitude unknown and a brief one
    costs little. Returns None for a sample within range, or when ``gyro_range_rad_s`` is None.
    """
    if gyro_range_rad_s is None or np.abs(gyro).max() < SATURATED * gyro_range_rad_s:
        return None
    return (gyro_range_rad_s * dt) ** 2


def untrusted_gyro_noise(gyro_range_rad_s: float | None, scale, gap_accel_rad_s2: float | None = None) -> Kernel | None:
    """A model's ``input_noise`` (:class:`~quadlib.Model`) for a gyro-driven step whose sample
    cannot be fully trusted: ``diag(scale) · v`` with ``v`` the variance per axis of the unknown turn
    (``scale`` maps it onto the error state: 1 per rotation axis, ¼ per quaternion component, 0 for
    states the gyro does not move). Two cases, each off when its argument is None:

    * a saturated sample, ``v`` from :func:`saturated_step_variance` (``gyro_range_rad_s``);
    * a held sample, one that stands in for a missing one (:func:`gyro_with_gaps`, the input's fourth
      column ``τ``, the seconds since the last real sample): the rate may have changed by up to about
      ``α τ`` since, ``α = gap_accel_rad_s2``, so ``v = (α τ Δt)²``. One missing sample costs
      almost nothing; half a second without the gyro leaves the attitude unknown.

    None when both are off. The kernel :func:`~quadlib.kernels.attitude.gyro_input_noise`, which the
    compiled engine calls too."""
    if gyro_range_rad_s is None and gap_accel_rad_s2 is None:
        return None
    scale = np.asarray(scale, dtype=float).reshape(-1)
    full_scale = 0.0 if gyro_range_rad_s is None else as_positive("gyro_range_rad_s", gyro_range_rad_s)
    alpha = 0.0 if gap_accel_rad_s2 is None else as_positive("gap_accel_rad_s2", gap_accel_rad_s2)
    return Kernel("input_noise", gyro_input_noise, [full_scale, scale.size, *scale, alpha])


def gyro_with_gaps(t: np.ndarray, gyro: np.ndarray) -> np.ndarray:
    """``(N, 4)``: the gyro rows with each missing (NaN) row holding the last real one before it (the
    first real one before any), and a fourth column ``τ``, the seconds since that last real row
    (0 for a real row): the input of a model built with ``gap_accel_rad_s2``
    (:func:`untrusted_gyro_noise`)."""
    missing = np.isnan(gyro).any(axis=1)
    if missing.all():
        raise ValueError("gyro: expected at least one complete reading, got none")
    rows = np.arange(len(gyro))
    last = np.maximum.accumulate(np.where(missing, -1, rows))
    first = int(np.argmax(~missing))
    source = np.where(last >= 0, last, first)
    since = np.where(missing & (last >= 0), t - t[np.maximum(last, 0)], 0.0)
    return np.column_stack([gyro[source], since])


def as_imu_stream(name: str, value, n: int, width: int | None = 3, required: bool = True) -> np.ndarray | None:
    """One IMU stream as a read-only ``(n, width)`` (or ``(n,)``) float copy, NaN rows allowed
    (missing samples), or a named error; ``None`` passes when the stream is not ``required``."""
    shape = (n,) if width is None else (n, width)
    if value is None:
        if required:
            raise TypeError(f"{name}: expected an array of shape {shape}, got None")
        return None
    arr = np.array(as_float_array(name, value))  # a copy: the log is frozen, the caller's is not
    if arr.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {arr.shape}")
    if np.isinf(arr).any():
        raise ValueError(f"{name}: expected finite values or NaN for missing, got inf")
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True)
class ImuLog:
    """IMU samples on one time grid (``N`` samples), body frame FRD; NaN rows are missing samples.

    Parameters
    ----------
    t : (N,) array_like
        Strictly increasing sample times [s].
    gyro : (N, 3) array_like
        Body rates [rad/s]; ``gyro[k]`` holds over ``[t[k], t[k+1])``.
    accel : (N, 3) array_like
        Specific force ``R_nbᵀ (a_n − g_n)`` [m/s²].
    mag : (N, 3) array_like, optional
        Magnetic field in the body frame (any unit; the estimator's reference field uses the same).
    airspeed : (N,) array_like, optional
        Airspeed along body x [m/s] (fixed-wing aircraft).
    """

    t: np.ndarray
    gyro: np.ndarray
    accel: np.ndarray
    mag: np.ndarray | None = None
    airspeed: np.ndarray | None = None

    def __post_init__(self):
        t = np.array(as_times("ImuLog.t", self.t))
        t.setflags(write=False)
        object.__setattr__(self, "t", t)
        n = t.size
        for name, width in (("gyro", 3), ("accel", 3), ("mag", 3), ("airspeed", None)):
            object.__setattr__(self, name, as_imu_stream(f"ImuLog.{name}", getattr(self, name), n, width,
                                                         required=name in ("gyro", "accel")))

    def __len__(self) -> int:
        return self.t.size

    @property
    def dt(self) -> np.ndarray:
        """(N − 1,) sample periods [s]."""
        return np.diff(self.t)

    def slice(self, start: int | None = None, stop: int | None = None) -> ImuLog:
        """The samples ``start:stop`` as a new log."""
        s = slice(start, stop)
        return ImuLog(self.t[s], self.gyro[s], self.accel[s], None if self.mag is None else self.mag[s],
                      None if self.airspeed is None else self.airspeed[s])


def rates_to_interval_start(gyro: np.ndarray) -> np.ndarray:
    """Gyro rows stamped at the end of their interval, ``gyro[k]`` over ``(t[k−1], t[k]]`` (VQF, BROAD,
    most IMUs), moved to :class:`ImuLog`'s convention, ``gyro[k]`` over ``[t[k], t[k+1])``: each row
    one earlier, the last (the rate after the log ends) NaN."""
    return np.vstack([gyro[1:], np.full((1, gyro.shape[1]), np.nan)])
