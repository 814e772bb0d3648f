"""How well an IMU log and its GPS agree, before any filter: the checks that fix a GPS delay and the
accelerometer's effective noise on a real log.

Between two GPS fixes ``T`` apart the accelerometer, turned into the earth frame with an attitude and
given back gravity, integrates to the change of velocity the receiver saw:
``Σ (R f + g_n) Δt ≈ v_gps(t + T) − v_gps(t)``. What is left over says two things. Its size, over
windows of a few fixes, is the IMU's velocity error per window (aliased vibration, the attitude's
error) plus twice the GPS velocity noise. And shifting the fixes in time until it is smallest
measures the receiver's delay.
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import GRAVITY_N
from quadlib.geometry.quaternion import as_unit_quaternions, quat_to_dcm
from quadlib.imu import ImuLog
from quadlib.samples import Samples
from quadlib.validation import as_count, as_float_array, as_instance, as_positive, as_vector

__all__ = ["accel_noise_equivalent", "velocity_change_mismatch"]


def velocity_change_mismatch(log: ImuLog, q_nb, gps: Samples, delay_s: float = 0.0, fixes: int = 5) -> np.ndarray:
    """``(K − fixes, 3)``: the IMU's velocity change over ``fixes`` GPS intervals minus the GPS's,
    with each fix taken to describe the time ``delay_s`` before it was logged.

    ``q_nb`` (N, 4) is an attitude at every IMU sample (the autopilot's, or an estimate); the
    accelerometer is integrated with the rectangle rule and read at the fixes' times by linear
    interpolation. ``gps.z`` is ``[pn, pe, pd, vn, ve, vd]``; NaN fixes give NaN rows.
    """
    log, gps = as_instance("log", log, ImuLog), as_instance("gps", gps, Samples)
    q = as_unit_quaternions("q_nb", q_nb)
    if q.shape != (len(log), 4):
        raise ValueError(f"q_nb: expected one attitude per IMU sample, shape ({len(log)}, 4), got {q.shape}")
    if gps.z.ndim != 2 or gps.z.shape[1] != 6:
        raise ValueError(f"gps: expected samples of [pn, pe, pd, vn, ve, vd], shape (K, 6), got {gps.z.shape}")
    delay = as_positive("delay_s", delay_s, allow_zero=True)
    fixes = as_count("fixes", fixes, high=gps.t.size - 1)
    a_n = np.einsum("nij,nj->ni", quat_to_dcm(q), np.nan_to_num(log.accel)) + GRAVITY_N
    v_imu = np.vstack([np.zeros(3), np.cumsum(a_n[:-1] * log.dt[:, None], axis=0)])
    at_fix = np.column_stack([np.interp(gps.t - delay, log.t, v_imu[:, i]) for i in range(3)])
    return (at_fix[fixes:] - at_fix[:-fixes]) - (gps.z[fixes:, 3:] - gps.z[:-fixes, 3:])


def accel_noise_equivalent(mismatch, window_s: float, sample_period_s: float, gps_vel_sigma_m_s) -> np.ndarray:
    """``(3,)``: the white accelerometer noise per sample [m/s²] that would explain ``mismatch``
    (from :func:`velocity_change_mismatch`) over windows of ``window_s``: white noise ``σ`` per sample
    integrates to ``σ Δt √(window/Δt)``, and the two GPS velocities add ``2 σ_v²``."""
    e = as_float_array("mismatch", mismatch)
    if e.ndim != 2 or e.shape[1] != 3 or np.isnan(e).all():
        raise ValueError(f"mismatch: expected (K, 3) differences with some finite rows, got shape {e.shape}")
    rms2 = np.nanmean(e**2, axis=0)
    gps_var = 2.0 * as_vector("gps_vel_sigma_m_s", gps_vel_sigma_m_s, 3) ** 2
    dt = as_positive("sample_period_s", sample_period_s)
    n = as_positive("window_s", window_s) / dt
    return np.sqrt(np.clip(rms2 - gps_var, 0.0, None)) / (dt * np.sqrt(n))
