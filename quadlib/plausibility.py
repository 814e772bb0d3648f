"""Physics checks on a log before a one-call estimator filters it: units, and a sensor left unused.

A wrong unit does not crash a filter: an accelerometer in g has every gravity update rejected and
the attitude drifts on the gyro alone; a clock in milliseconds or a gyro in °/s turns the attitude
a thousand or fifty-seven times too far. These checks look at what the data say about themselves
and name the caller's argument, the unit expected and what was seen:

* the median interval between samples lies in [1e-4 s, 1 s] (ms and µs are named);
* the median accelerometer norm is near g₀ = 9.81 m/s² (a norm near 1 is "g, not m/s²");
* the gyro turns the accelerometer's direction as fast as that direction turns: for a specific
  force steady in the earth frame, ``d f_b/dt = −ω × f_b``; the least-squares scale between the
  two is 1 for rad/s and 1/57.3 for °/s (checked only when the log turns enough to tell);
* the magnetometer's direction turns as the gyro says (a warning: an MPU-9250's swapped axes);
* GPS positions that barely move while its velocities carry the vehicle metres away are degrees
  of latitude and longitude, not metres.

:func:`warn_unused` warns after a run when a sensor's update used under 1 % of its samples, and
says why: the plausibility checks or the χ² gate refused them, or there were none.
"""

from __future__ import annotations

import warnings

import numpy as np

from quadlib.constants import G0
from quadlib.geometry.quaternion import quat_from_rotvec, quat_to_dcm

__all__ = ["check_gps_metres", "check_imu_units", "check_mag_frame", "warn_unused"]


def check_imu_units(t: np.ndarray, gyro: np.ndarray, accel: np.ndarray, names=("t", "gyr", "acc")) -> None:
    """Raise ``ValueError`` naming ``names`` when the time, gyro or accelerometer units look wrong.

    ``t`` (N,) [s], ``gyro`` (N, 3) [rad/s], ``accel`` (N, 3) [m/s²]; NaN rows are ignored.
    """
    t_name, gyro_name, accel_name = names
    for name, values, what in ((gyro_name, gyro, "rate"), (accel_name, accel, "specific force")):
        if not np.isfinite(values).all(axis=1).any():
            raise ValueError(f"{name}: expected at least one finite {what} (a row without NaN), got none")
    if t.size > 1:
        dt = float(np.median(np.diff(t)))
        if not 1e-4 <= dt <= 1.0:
            guess = " (it looks like ms)" if 0.5 <= dt < 100.0 else " (it looks like µs)" if 100.0 <= dt <= 1e5 else ""
            raise ValueError(f"{t_name}: expected times in seconds with a median interval between 1e-4 s and 1 s, "
                             f"got a median interval of {dt:.6g}{guess}")
    norm = np.linalg.norm(accel, axis=1)
    norm = norm[np.isfinite(norm)]
    if norm.size:
        median = float(np.median(norm))
        if 0.5 <= median <= 2.0:
            raise ValueError(f"{accel_name}: expected specific force in m/s² (median norm near {G0:.2f}), got a "
                             f"median norm of {median:.3f}: it looks like g; multiply by {G0}")
        if not 0.5 * G0 <= median <= 2.0 * G0:
            raise ValueError(f"{accel_name}: expected specific force in m/s² (median norm near {G0:.2f}), got a "
                             f"median norm of {median:.4g}")
    ratio = degrees_likelier(t, gyro, accel)
    if ratio is not None and ratio > 2.0:
        raise ValueError(f"{gyro_name}: expected rates in rad/s, got rates that turn {accel_name}'s direction "
                         f"{ratio:.0f} times worse than the same numbers read as °/s: multiply by π/180")


def _prediction_errors(t, gyro, vectors, usable, scales, window_s: float = 0.2, min_turn_rad: float = 0.1):
    """Median error of predicting a body-frame direction ``window_s`` ahead by turning it with the
    gyro's integral times each of ``scales`` (0: not turned), over windows whose ends are
    ``usable`` and over which the gyro as given turns by more than ``min_turn_rad`` (where the
    readings differ); None with fewer than 50 such windows."""
    if t.size < 3:
        return None
    step = max(1, int(round(window_s / max(float(np.median(np.diff(t))), 1e-9))))
    rates = np.where(np.isfinite(gyro), gyro, 0.0) * np.r_[np.diff(t), 0.0][:, None]
    integral = np.vstack([np.zeros((1, 3)), np.cumsum(rates, axis=0)])
    k = np.arange(0, t.size - step, max(1, step // 4))
    theta = integral[k + step] - integral[k]
    keep = usable[k] & usable[k + step] & (np.linalg.norm(theta, axis=1) > min_turn_rad)
    k, theta = k[keep], theta[keep]
    if k.size < 50:
        return None
    u = vectors / np.linalg.norm(vectors, axis=1, keepdims=True)
    errors = []
    for scale in scales:  # the body turned by scale·θ sees a fixed direction turned back: R(θ)ᵀ u
        predicted = np.einsum("nji,nj->ni", quat_to_dcm(quat_from_rotvec(scale * theta)), u[k])
        errors.append(float(np.median(np.linalg.norm(u[k + step] - predicted, axis=1))))
    return errors


def degrees_likelier(t: np.ndarray, gyro: np.ndarray, accel: np.ndarray) -> float | None:
    """How much better the accelerometer's direction follows the gyro read as °/s than as rad/s:
    the ratio of the two prediction errors (:func:`_prediction_errors`, on samples whose norm is
    within 5 % of g₀), well above 1 when the gyro is in °/s; None when the log turns too little."""
    calm = np.abs(np.linalg.norm(accel, axis=1) - G0) < 0.05 * G0
    errors = _prediction_errors(t, gyro, accel, calm, (1.0, np.pi / 180.0))
    return None if errors is None else errors[0] / max(errors[1], 1e-12)


def field_follows_gyro(t: np.ndarray, gyro: np.ndarray, mag: np.ndarray) -> float | None:
    """The magnetometer's direction predicted by the gyro, against not turned at all: the ratio of
    the two errors (:func:`_prediction_errors`), well below 1 for a magnetometer in the gyro's frame
    and near or above 1 when its axes are swapped or in another frame; None when the log turns too
    little."""
    errors = _prediction_errors(t, gyro, mag, np.isfinite(mag).all(axis=1), (1.0, 0.0))
    return None if errors is None else errors[0] / max(errors[1], 1e-12)


def check_mag_frame(t: np.ndarray, gyro: np.ndarray, mag: np.ndarray, names=("mag", "gyr")) -> None:
    """Warn when the magnetometer's direction does not turn as the gyro says
    (:func:`field_follows_gyro` above 1): its axes are swapped or in another frame (an MPU-9250's
    magnetometer has x and y swapped and z reversed against its gyro), or a magnet turns with it."""
    ratio = field_follows_gyro(t, gyro, mag)
    if ratio is not None and ratio > 1.0:
        warnings.warn(f"{names[0]}: expected a field in {names[1]}'s frame, got a field whose direction the gyro "
                      f"predicts {ratio:.2f} times worse than not turning it at all (axes swapped, or another frame?)",
                      stacklevel=3)


def check_gps_metres(gps_t: np.ndarray, gps: np.ndarray, name: str = "gps") -> None:
    """Raise ``ValueError`` naming ``name`` when ``[pn, pe, pd, vn, ve, vd]`` fixes hold degrees.

    The test: the velocities, integrated over the log, carry the vehicle over 10 m horizontally,
    while the horizontal positions change by under 1 % of that.
    """
    ok = np.isfinite(gps).all(axis=1)
    if ok.sum() < 3:
        return
    t, z = gps_t[ok], gps[ok]
    travelled = np.cumsum(z[1:, 3:5] * np.diff(t)[:, None], axis=0)
    by_velocity = float(np.max(np.linalg.norm(travelled, axis=1)))
    by_position = float(np.max(np.linalg.norm(z[:, :2] - z[0, :2], axis=1)))
    if by_velocity > 10.0 and by_position < 0.01 * by_velocity:
        raise ValueError(f"{name}: expected NED positions [m] about a reference point, got positions that move "
                         f"{by_position:.3g} while the velocities move {by_velocity:.0f} m (latitude and longitude "
                         "in degrees? convert with quadlib.geometry.geodetic_to_ned)")


def warn_unused(sensors: dict, streams: dict | None = None, fraction: float = 0.01) -> None:
    """Warn for each sensor trace whose update used under ``fraction`` of the samples it had.

    Without ``streams``: of the samples offered to the filter (present and plausible), when at
    least 100 were, named by the trace. With ``streams`` (trace name → the caller's argument and
    its ``(N,)`` rows that hold a reading): of the readings the caller gave, named by the argument,
    with how many the plausibility checks and how many the χ² gate refused.
    """
    for name, trace in sensors.items():
        rejected, used = int(np.sum(trace.rejected)), int(np.sum(trace.used))
        if streams is None or name not in streams:
            offered = int(trace.t.size - np.sum(trace.duplicate | trace.missing))
            if offered >= 100 and used < fraction * offered:
                warnings.warn(f"{name}: used {used} of the {offered} samples offered ({rejected} rejected by the χ² "
                              "gate); check its units, frame and the declination", stacklevel=3)
            continue
        argument, present = streams[name]
        given = int(np.sum(present))
        if given >= 100 and used < fraction * given:
            failed = given - used - rejected
            warnings.warn(f"{argument}: the {name} update used {used} of its {given} readings ({failed} failed the "
                          f"plausibility checks, {rejected} were refused by the χ² gate); check its unit, frame and "
                          "the declination", stacklevel=3)
