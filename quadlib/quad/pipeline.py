"""The blog's "simplest pipeline": every state from one sensor, no filter beyond a complementary one.

State (the blog's eq. 1): ``[x, y, z, ẋ, ẏ, ż, φ, θ, ψ, φ̇, θ̇, ψ̇]`` (NED, SI units). Position from
the GPS (x, y) and the barometer (z = −altitude); velocities as finite differences of
consecutive samples of the same sensor; roll and pitch from a complementary filter; yaw from
the magnetometer. Each value is held until the next sample (missing samples are skipped), so
it is the baseline a filter has to beat.
"""

from __future__ import annotations

import numpy as np

from quadlib.geometry.rotations import wrap_angle
from quadlib.samples import Samples
from quadlib.validation import as_finite_array, as_instance, as_times

__all__ = ["simple_pipeline"]


def _held(t, sample_t, values, name):
    """Latest valid sample at or before each ``t`` and the finite difference of the last two."""
    values = np.asarray(values, dtype=float).reshape(len(sample_t), -1)
    ok = ~np.isnan(values).any(axis=1)
    st, vals = np.asarray(sample_t, dtype=float)[ok], values[ok]
    if st.size < 2:
        raise ValueError(f"{name}: expected at least two valid samples, got {st.size}")
    idx = np.searchsorted(st, t, side="right") - 1
    rate = np.diff(vals, axis=0) / np.diff(st)[:, None]
    held = np.where(idx[:, None] >= 0, vals[np.clip(idx, 0, None)], np.nan)
    slope = np.where(idx[:, None] >= 1, rate[np.clip(idx - 1, 0, None)], np.nan)
    return held, slope, vals, st, idx


def simple_pipeline(t, roll_pitch, gps, baro, mag_yaw) -> np.ndarray:
    """The blog's pipeline on a time grid ``t``: ``(N, 12)`` states (NaN before the first samples).

    Parameters
    ----------
    t : (N,) times [s]
    roll_pitch : (N, 2) roll and pitch [rad] from a complementary filter, at ``t``
    gps : Samples with ``z`` of shape (K, ≥2), NED ``x, y`` first [m]
    baro : Samples with ``z`` of shape (K, 1), altitude [m]
    mag_yaw : Samples with ``z`` of shape (K, 1), heading [rad]
    """
    t = as_times("t", t)
    gps, baro, mag_yaw = (as_instance(n, s, Samples) for n, s in (("gps", gps), ("baro", baro), ("mag_yaw", mag_yaw)))
    roll_pitch = as_finite_array("roll_pitch", roll_pitch, ndim=2)
    if roll_pitch.shape != (t.size, 2):
        raise ValueError(f"roll_pitch: expected shape ({t.size}, 2), got {roll_pitch.shape}")
    xy, vxy, *_ = _held(t, gps.t, np.asarray(gps.z)[:, :2], "gps")
    alt, valt, *_ = _held(t, baro.t, baro.z, "baro")
    yaw, _, yaws, yaw_t, idx = _held(t, mag_yaw.t, mag_yaw.z, "mag_yaw")
    yaw_rate = wrap_angle(np.diff(yaws[:, 0])) / np.diff(yaw_t)  # a wrap is not a spin
    yaw_rate = np.where(idx >= 1, yaw_rate[np.clip(idx - 1, 0, None)], np.nan)
    rp_rate = np.gradient(roll_pitch, t, axis=0)
    return np.column_stack([xy, -alt, vxy, -valt, roll_pitch, yaw, rp_rate, yaw_rate])
