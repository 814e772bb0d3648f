"""The IMU's streams averaged for the orientation filter: the samples at rest (its zero-rate
update) and the accelerometer low-passed in a frame that does not turn with the body (its gravity).
The loops are compiled kernels (:mod:`quadlib.kernels.lowpass`); these are their readable faces."""

from __future__ import annotations

import numpy as np

from quadlib.imu import ImuLog, gyro_with_gaps
from quadlib.kernels.lowpass import calm_samples, inertial_lowpass_pass
from quadlib.validation import as_bool, as_finite_array, as_positive

__all__ = ["held_rows", "inertial_lowpass", "rest_mask"]


def rest_mask(log: ImuLog, gyro_rad_s: float, accel_m_s2: float, min_s: float, tau_s: float = 0.5) -> np.ndarray:
    """``(N,)`` bool: the samples where the sensor is at rest (VQF's test, Laidig & Seel 2023, §4).

    Each stream is low-passed (first order, ``tau_s``); a sample is calm when the gyro is within
    ``gyro_rad_s`` of its low-pass and the accelerometer within ``accel_m_s2`` of its own, and the
    sensor is at rest once it has been calm for ``min_s`` seconds. Missing samples are not calm.
    """
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    gyro_th, accel_th = as_positive("gyro_rad_s", gyro_rad_s), as_positive("accel_m_s2", accel_m_s2)
    min_s, tau = as_positive("min_s", min_s), as_positive("tau_s", tau_s)
    calm = calm_samples(log.t, log.gyro, log.accel, gyro_th, accel_th, tau)
    starts = calm & ~np.r_[False, calm[:-1]]  # the first sample of each calm run
    since = log.t[np.maximum.accumulate(np.where(starts, np.arange(len(log)), 0))]
    return calm & (log.t - since >= min_s)


def held_rows(values: np.ndarray) -> np.ndarray:
    """``values`` with each row that holds a NaN replaced by the last complete row before it
    (zeros before the first): a missing gyro sample turns the frame as the one before it did."""
    complete = ~np.isnan(values).any(axis=1)
    if complete.all():
        return values
    last = np.maximum.accumulate(np.where(complete, np.arange(len(values)), -1))
    return np.where((last >= 0)[:, None], values[np.maximum(last, 0)], 0.0)


def inertial_lowpass(log: ImuLog, tau_s: float, gyro_bias=None, two_sided: bool = False,
                     gap_accel_rad_s2: float | None = None, second_order: bool = False) -> np.ndarray:
    """The accelerometer low-passed in a frame that does not turn with the body, ``(N, 3)`` in the
    body frame.

    Each sample is turned into a frame integrated from the gyro alone, ``a_I = R(q_I) a_b``,
    averaged there by a first-order low-pass of time constant ``tau_s``, and turned back,
    ``R(q_I)ᵀ ā_I``. Gravity is constant in that frame and passes; a translation's accelerations
    average out, since its velocity stays bounded (VQF's idea, Laidig & Seel 2023, §3). The
    gyro's drift blurs the result: a bias ``b`` tilts the average by about ``|b| τ``, so
    ``gyro_bias`` ((3,) or one row per sample [rad/s]) is subtracted first. A missing gyro sample
    (a NaN row) turns the frame at the rate before it; with ``gap_accel_rad_s2`` (``α``), once a gap
    of ``τ`` seconds may have turned it by more than a degree, ``α τ²/2``, the frame is lost and the
    average starts afresh at the next sample. Missing accelerometer samples hold the
    average. Every other sample counts, the violent ones too: the accelerations cancel only as a
    whole, and an average that left out the largest of them would keep the rest (chapter 16 shows
    it on BROAD's fast-translation trial 16, with the samples 50 m/s² off g₀ left out).

    ``two_sided`` (offline use): the mean of the low-pass run forwards and the same run backwards
    in time, a symmetric window around each sample that does not lag.

    ``second_order``: VQF's second-order Butterworth low-pass instead (cut-off ``√2/(2π τ)``, its
    coefficients from each step's Δt; the mean of the first ``τ`` seconds until then). It passes
    gravity alike; above the cut-off it damps a translation's accelerations as ``1/f²``, not ``1/f``:
    ``π f τ`` times more at frequency ``f``, about 7 times at ten times its cut-off.
    """
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    tau, two_sided = as_positive("tau_s", tau_s), as_bool("two_sided", two_sided)
    second_order = as_bool("second_order", second_order)
    gyro = log.gyro
    if gyro_bias is not None:
        bias = as_finite_array("gyro_bias", gyro_bias)
        if bias.shape not in ((3,), gyro.shape):
            raise ValueError(f"gyro_bias: expected shape (3,) or {gyro.shape}, got {bias.shape}")
        gyro = gyro - bias
    usable = ~np.isnan(log.accel).any(axis=1)
    lost = np.zeros(len(log), bool)
    if gap_accel_rad_s2 is not None:  # the step into sample k turned with row k − 1
        alpha = as_positive("gap_accel_rad_s2", gap_accel_rad_s2)
        held_for = gyro_with_gaps(log.t, gyro)[:, 3]
        lost[1:] = alpha * (held_for[:-1] + np.diff(log.t)) ** 2 / 2 > np.radians(1.0)
        lost[1:] &= held_for[:-1] > 0
    gyro = np.ascontiguousarray(held_rows(gyro), dtype=float)
    forward = inertial_lowpass_pass(log.t, gyro, log.accel, usable, lost, tau, False, second_order)
    if not two_sided:
        return forward
    backward = inertial_lowpass_pass(log.t, gyro, log.accel, usable, lost, tau, True, second_order)
    both = 0.5 * (forward + backward)
    return np.where(np.isnan(forward), backward, np.where(np.isnan(backward), forward, both))
