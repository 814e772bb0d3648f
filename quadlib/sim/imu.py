"""What an IMU reads along a true motion: the one IMU simulator of every vehicle.

.. math::

    \\omega_m = \\omega_b + b_k + n_\\omega, \\quad b_k = b_0 + \\sum_{j \\le k} w_j, \\quad
    f_m = f_b + n_f, \\quad m_m = R(q_{nb})^\\top m_n + n_m

with white noises ``n`` and the bias random walk ``w`` drawn from :class:`~quadlib.imu.ImuNoise`.
Draw order (fixed, so a seed gives the same log everywhere): bias walk (only when it is
non-zero), gyro, accelerometer, magnetometer (only when a field is given).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.constants import GRAVITY_N
from quadlib.geometry.quaternion import as_unit_quaternions, quat_to_dcm
from quadlib.imu import ImuLog, ImuNoise
from quadlib.validation import as_count, as_rng, as_times, as_vector, as_vectors3

__all__ = ["BodyMotion", "imu_samples", "specific_force_at_rest"]


@dataclass(frozen=True)
class BodyMotion:
    """A true motion as an IMU sees it: ``t`` (N,), ``q_nb`` (N, 4), ``omega_b`` (N, 3) [rad/s]
    with ``omega_b[k]`` turning ``q_nb[k]`` into ``q_nb[k+1]``, and ``f_b`` (N, 3) specific force
    [m/s²]. The flights of every vehicle extend it."""

    t: np.ndarray
    q_nb: np.ndarray
    omega_b: np.ndarray
    f_b: np.ndarray

    def __post_init__(self):
        t = as_times(f"{type(self).__name__}.t", self.t)
        n = t.size
        q = as_unit_quaternions(f"{type(self).__name__}.q_nb", self.q_nb)
        for name, value in (("q_nb", q), ("omega_b", as_vectors3(f"{type(self).__name__}.omega_b", self.omega_b)),
                            ("f_b", as_vectors3(f"{type(self).__name__}.f_b", self.f_b))):
            if value.shape[0:1] != (n,) or value.ndim != 2:
                raise ValueError(f"{type(self).__name__}.{name}: expected one row per time, ({n}, "
                                 f"{value.shape[-1]}), got {value.shape}")

    @property
    def dt(self) -> float:
        """Sample period [s] (the motions here are uniformly sampled)."""
        return float(self.t[1] - self.t[0])


def specific_force_at_rest(q_nb) -> np.ndarray:
    """``−R(q_nb)ᵀ g_n``, ``(N, 3)``: the accelerometer of a vehicle that does not accelerate."""
    return -np.einsum("nji,j->ni", quat_to_dcm(as_unit_quaternions("q_nb", q_nb)), GRAVITY_N)


def imu_samples(motion, noise: ImuNoise, rng, field_n=None, mag_every: int = 1, accel_every: int = 1) -> ImuLog:
    """Gyro, accelerometer and (with ``field_n``) magnetometer samples along ``motion``.

    Parameters
    ----------
    motion : BodyMotion (every vehicle's flight is one)
    noise : ImuNoise
    rng : numpy.random.Generator
    field_n : (3,) array_like, optional
        The Earth's field in NED (:func:`quadlib.constants.earth_field_ned`); no magnetometer without it.
    mag_every, accel_every : int
        Keep every k-th magnetometer / accelerometer sample; the others are NaN rows.

    Returns
    -------
    ImuLog
    """
    if not isinstance(motion, BodyMotion):
        raise TypeError(f"motion: expected a BodyMotion (a vehicle's flight is one), got {type(motion).__name__}")
    if not isinstance(noise, ImuNoise):
        raise TypeError(f"noise: expected an ImuNoise, got {type(noise).__name__}")
    rng = as_rng(rng)
    mag_every, accel_every = as_count("mag_every", mag_every), as_count("accel_every", accel_every)
    t = np.asarray(motion.t, dtype=float)
    n = t.size
    walk = 0.0
    if noise.gyro_bias_walk_rad_s_sqrt_s > 0:
        walk = np.cumsum(rng.standard_normal((n, 3)) * (noise.gyro_bias_walk_rad_s_sqrt_s * np.sqrt(t[1] - t[0])),
                         axis=0)
    gyro = (motion.omega_b + np.asarray(noise.gyro_bias_rad_s, dtype=float) + walk
            + rng.standard_normal((n, 3)) * noise.gyro_sigma_rad_s)
    if noise.gyro_range_rad_s is not None:
        gyro = np.clip(gyro, -noise.gyro_range_rad_s, noise.gyro_range_rad_s)
    accel = motion.f_b + rng.standard_normal((n, 3)) * np.asarray(noise.accel_sigma_m_s2, dtype=float)
    accel[np.arange(n) % accel_every != 0] = np.nan
    mag = None
    if field_n is not None:
        mag = np.einsum("nji,j->ni", quat_to_dcm(motion.q_nb), as_vector("field_n", field_n, 3))
        mag = mag + rng.standard_normal((n, 3)) * noise.mag_sigma
        mag[np.arange(n) % mag_every != 0] = np.nan
    return ImuLog(t, gyro, accel, mag)
