"""Plausibility checks for the vector sensors of an attitude estimator.

An accelerometer measures gravity only when the vehicle does not accelerate, and a magnetometer
measures the Earth's field only when nothing else is near it. A filter that believes them
regardless is pulled tens of degrees off by a shock, a free fall, a magnet or a stuck sensor. So
each sample is first checked against what the sensor should read, and an implausible one is
skipped — no state, no timer: trust returns with the first plausible sample.

* accelerometer: its norm against g₀ (a shock, strong vibration, free fall, a sustained
  manoeuvre);
* magnetometer: its norm against the reference field's (a magnet, a current, a saturated
  sensor); its dip — the angle between the measured field and the horizontal plane that the
  accelerometer gives — against the reference inclination (a disturbance that turns the field
  without changing its strength); and runs of bit-identical readings (a stuck sensor: real
  readings carry noise, so several equal ones in a row mean the value is frozen).

A filter that has an attitude of its own can measure the dip against it instead
(``plausible_mag(..., q_nb=...)``): the accelerometer's down swings with every translation, the
estimate's does not. And a disturbance seldom ends the moment its first plausible sample arrives
(a magnet moving away passes through plausible values on its way): :func:`settled` keeps a
sample out until its stream has been plausible for a while.

VQF and many AHRS use the same two tests; the thresholds here are wide enough that sensor
noise and ordinary flight never trip them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.constants import G0
from quadlib.geometry.quaternion import quat_to_dcm
from quadlib.kernels.lowpass import undisturbed_field_pass
from quadlib.samples import stuck_rows
from quadlib.validation import (
    as_float_array,
    as_instance,
    as_mask,
    as_positive,
    as_quaternions,
    as_times,
    as_vectors3,
    check_fields,
)

NEW_FIELD_MIN_RATE_RAD_S = float(np.radians(20.0))  # VQF's magNewMinGyr

__all__ = ["SensorChecks", "plausible_accel", "plausible_mag", "settled", "undisturbed_field"]


@dataclass(frozen=True)
class SensorChecks:
    """When an accelerometer or magnetometer sample is implausible and skipped (``None``: no check).

    Parameters
    ----------
    accel_norm_tolerance_m_s2 : float
        Largest ``| |f| − g₀ |`` [m/s²] (2 m/s²: a fifth of g₀; free fall reads 0).
    mag_norm_tolerance : float
        Largest relative deviation of ``|m|`` from the reference field's strength (0.2: ±20 %).
    mag_dip_tolerance_rad : float
        Largest difference between the measured and the reference dip [rad] (10°).
    mag_stuck_samples : int
        A magnetometer sample equal to the ``n − 1`` present samples before it is taken as
        stuck (5; from the fifth equal reading on, until the value changes).
    """

    accel_norm_tolerance_m_s2: float | None = 2.0
    mag_norm_tolerance: float | None = 0.2
    mag_dip_tolerance_rad: float | None = float(np.radians(10.0))
    mag_stuck_samples: int | None = 5

    def __post_init__(self):
        check_fields(self, {"accel_norm_tolerance_m_s2": "optional positive", "mag_norm_tolerance": "optional positive",
                            "mag_dip_tolerance_rad": "optional positive", "mag_stuck_samples": "optional count"})


def _samples3(name, value):
    v = as_float_array(name, value)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"{name}: expected an (N, 3) array (NaN rows for missing samples), got shape {v.shape}")
    return v


def plausible_accel(accel, checks: SensorChecks) -> np.ndarray:
    """``(N,)`` bool: the sample is there and its norm is within tolerance of g₀."""
    checks = as_instance("checks", checks, SensorChecks)
    a = _samples3("accel", accel)
    norm = np.linalg.norm(a, axis=-1)
    ok = np.isfinite(norm)
    if checks.accel_norm_tolerance_m_s2 is not None:
        with np.errstate(invalid="ignore"):
            ok &= np.abs(norm - G0) <= checks.accel_norm_tolerance_m_s2
    return ok


def plausible_mag(mag, accel, field_n, checks: SensorChecks, *, q_nb=None) -> np.ndarray:
    """``(N,)`` bool: the sample is there, its norm is within tolerance of ``|field_n|`` and, where
    the accelerometer gives a plausible down direction, its dip is within tolerance of the reference.

    ``field_n`` is the reference field in NED, in the magnetometer's unit. ``q_nb`` ((N, 4), an
    attitude estimate per sample): the dip is measured against its down direction instead, and
    ``accel`` is not used (it may be None).
    """
    checks = as_instance("checks", checks, SensorChecks)
    m = _samples3("mag", mag)
    if q_nb is None:
        a = _samples3("accel", accel)
        if a.shape != m.shape:
            raise ValueError(f"accel: expected the shape of mag {m.shape}, got {a.shape}")
    else:
        q = as_quaternions("q_nb", q_nb)
        if q.shape != (m.shape[0], 4):
            raise ValueError(f"q_nb: expected one quaternion per mag sample, shape {(m.shape[0], 4)}, got {q.shape}")
    field = as_vectors3("field_n", field_n)
    strength = float(np.linalg.norm(field))
    norm = np.linalg.norm(m, axis=-1)
    ok = np.isfinite(norm) & (norm > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        if checks.mag_norm_tolerance is not None:
            ok &= np.abs(norm / strength - 1.0) <= checks.mag_norm_tolerance
        if checks.mag_dip_tolerance_rad is not None:
            if q_nb is None:
                down_known = plausible_accel(a, checks) & ok
                down = -a / np.linalg.norm(a, axis=-1, keepdims=True)
            else:  # NED's down in the body frame: the third row of R(q)
                down_known, down = np.isfinite(q).all(axis=-1), quat_to_dcm(q)[..., 2, :]
            dip = np.arcsin(np.clip(np.sum(m * down, axis=-1) / norm, -1.0, 1.0))
            reference_dip = np.arcsin(field[2] / strength)
            ok &= ~down_known | (np.abs(dip - reference_dip) <= checks.mag_dip_tolerance_rad)
    if checks.mag_stuck_samples is not None:
        ok &= ~stuck_rows(m, checks.mag_stuck_samples)
    return ok


def settled(ok, present, t, settle_s: float) -> np.ndarray:
    """``(N,)`` bool: ``ok`` where the stream has been plausible for at least ``settle_s`` seconds,
    counted from the last sample that was ``present`` but not ``ok`` (a missing sample neither
    breaks nor extends the run).

    ``ok``, ``present``: ``(N,)`` bool masks over the samples at times ``t`` [s].
    """
    t = as_times("t", t)
    ok, present = as_mask("ok", ok, t.size), as_mask("present", present, t.size)
    settle_s = as_positive("settle_s", settle_s)
    failed = present & ~ok
    last_failure = np.maximum.accumulate(np.where(failed, t, -np.inf))
    return ok & (t - last_failure >= settle_s)


def undisturbed_field(t, mag, down, field_n, checks: SensorChecks, *, settle_s: float = 0.0, tau_s: float = 0.05,
                      learn_tau_s: float | None = 20.0, gyro=None, new_field_s: float | None = None,
                      first_field_s: float | None = None) -> np.ndarray:
    """``(N,)`` bool: the magnetometer reads an undisturbed field, judged on a short average.

    :func:`plausible_mag` judges each reading alone, and a noisy magnetometer's single readings
    stray: on BROAD's, the dip of one reading scatters by several degrees, so a 10° tolerance
    with a settle time refused 44 % of the readings of trial 30 while the sensor moved, and the
    heading drifted between the few it kept. Here, as in VQF's magnetic disturbance rejection
    (Laidig & Seel 2023), the norm and the dip are first low-passed (first order, ``tau_s``), then
    checked with the tolerances of ``checks`` against a reference: ``field_n`` at the start (None:
    the first reading's norm, and its dip against ``down``), which
    then follows the averaged field (``learn_tau_s``; None: it stays) while the field is trusted,
    as the Earth's field changes from place to place (``tau_s`` 0 and ``learn_tau_s`` None: each
    reading judged alone against ``field_n``, as :func:`plausible_mag` does). The dip is measured
    against ``down`` ((N, 3), the down direction in the body frame, a unit vector per reading; NaN
    rows: unknown, the dip not checked). A reading is trusted once the checks have passed for
    ``settle_s`` seconds (from the start they pass); stuck readings never are. The average lets
    the first reading or two of a sudden disturbance through, until it crosses the tolerance.

    A reference can be wrong for good: taken from a first reading disturbed, or tilted by a
    translation's acceleration, or left behind in another room. So, as VQF accepts a new field
    (``magNewTime``), a refused field whose norm and dip hold within the tolerances of their own
    average for ``new_field_s`` seconds while the sensor turns faster than 20 °/s (``gyro``
    [rad/s], (N, 3), low-passed over 0.5 s) becomes the reference. A magnet fixed to the board
    turns with it, so its field's norm and dip change as the board turns; the Earth's do not.
    None (or no ``gyro``): the reference is never replaced.

    Without ``field_n``, the first reading's field is the reference, and a disturbed first reading
    (the sensor switched on beside a magnet) would keep the true field out until it has held while
    the sensor turns. So with ``first_field_s`` (VQF's ``magNewFirstTime``), that reference is on
    trial until it has been trusted for ``first_field_s`` seconds in all: until then a refused
    field that holds for ``first_field_s`` seconds replaces it, at rest too. A disturbance at the
    start that lasts less than ``first_field_s`` is replaced once the true field has held that long.
    A given ``field_n`` is never on trial.
    """
    checks = as_instance("checks", checks, SensorChecks)
    t = as_times("t", t)
    m = _samples3("mag", mag)
    d = _samples3("down", down)
    if m.shape[0] != t.size or d.shape[0] != t.size:
        raise ValueError(f"mag, down: expected one row per time, shape {(t.size, 3)}, got {m.shape} and {d.shape}")
    if field_n is None:
        strength, dip0 = np.nan, np.nan
    else:
        field = as_vectors3("field_n", field_n)
        strength = float(np.linalg.norm(field))
        dip0 = float(np.arcsin(field[2] / strength))
    settle_s = as_positive("settle_s", settle_s, allow_zero=True)
    tau = as_positive("tau_s", tau_s, allow_zero=True)
    learn = np.inf if learn_tau_s is None else as_positive("learn_tau_s", learn_tau_s)
    new_s = np.inf if new_field_s is None else as_positive("new_field_s", new_field_s)
    first_s = 0.0 if first_field_s is None else as_positive("first_field_s", first_field_s)
    if field_n is not None:
        first_s = 0.0
    if gyro is None:
        w, new_s = np.zeros((t.size, 3)), np.inf
    else:
        w = _samples3("gyro", gyro)
        if w.shape[0] != t.size:
            raise ValueError(f"gyro: expected one row per time, shape {(t.size, 3)}, got {w.shape}")
    norm_tol = np.inf if checks.mag_norm_tolerance is None else checks.mag_norm_tolerance
    dip_tol = np.inf if checks.mag_dip_tolerance_rad is None else checks.mag_dip_tolerance_rad
    ok = undisturbed_field_pass(t, np.nan_to_num(m, nan=0.0), d, w, strength, dip0,
                                norm_tol, dip_tol, settle_s, tau, learn, new_s, NEW_FIELD_MIN_RATE_RAD_S, first_s)
    if checks.mag_stuck_samples is not None:
        ok &= ~stuck_rows(m, checks.mag_stuck_samples)
    return ok
