"""Every orientation estimator on one real IMU log, in NED and BROAD's metric: the table of
chapter 16 and ``benchmarks/broad_orientation.py``.

quadlib's estimators were written for other sensors; each gets only what a user would give it on a
new log — the Earth's field as the log's first second at rest shows it (:func:`field_at_rest`) and
the log's units — and keeps its own noise values (Kesten's thesis, Salmony's document). The other
libraries' outputs are turned into NED with the fixed rotation between the frames: VQF and ahrs
Mahony return sensor → ENU, ahrs Madgwick sensor → NWU (x north, z up); their gyro input is each
sample's rate over the interval before it, as they integrate it (:func:`_arrays`).
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from quadlib.analysis.metrics import broad_errors
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.orientation import estimate_orientation
from quadlib.data.broad import ENU_TO_NED
from quadlib.fixedwing.estimate import error_state_ukf, estimate_fixedwing_attitude, salmony_ekf
from quadlib.fixedwing.model import FixedWingNoise
from quadlib.geometry.quaternion import quat_conjugate, quat_multiply
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog
from quadlib.validation import as_positive

__all__ = ["NWU_TO_NED", "error_components", "estimator_names", "field_at_rest",
           "orientation_estimate", "score_estimators"]

NWU_TO_NED = np.array([0.0, 1.0, 0.0, 0.0])
"""NWU → NED: 180° about north."""

UT_PER_GAUSS = 100.0


def field_at_rest(log: ImuLog, seconds: float = 1.0) -> tuple[float, float]:
    """The Earth's field as the first ``seconds`` of ``log`` show it, the sensor held still:
    its strength (the magnetometer's unit) and its dip below the horizon [rad], the angle between
    the field and the plane normal to the measured specific force (which points up at rest)."""
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    seconds = as_positive("seconds", seconds)
    if log.mag is None:
        raise ValueError("log.mag: expected magnetometer samples, got None")
    first = (log.t - log.t[0] <= seconds) & ~np.isnan(log.mag).any(axis=1) & ~np.isnan(log.accel).any(axis=1)
    if not first.any():
        raise ValueError(f"log: expected accelerometer and magnetometer samples in the first {seconds:g} s, got none")
    m, f = log.mag[first].mean(axis=0), log.accel[first].mean(axis=0)
    up_component = m @ f / np.linalg.norm(f)  # negative: the field points down
    return float(np.linalg.norm(m)), float(np.arcsin(np.clip(-up_component / np.linalg.norm(m), -1.0, 1.0)))


def _kesten(name):
    def estimate(log):
        strength, dip = field_at_rest(log)
        noise = replace(AttitudeNoise(), field_gauss=strength / UT_PER_GAUSS, inclination_rad=dip)
        gauss = ImuLog(log.t, log.gyro, log.accel, log.mag / UT_PER_GAUSS)
        start = attitude_from_accel_mag(log.accel[:1], log.mag[:1]).q_nb[0]
        return run_attitude_filter(FILTERS[name](noise), gauss, q0=start).q_nb
    return estimate


def _fixedwing(factory):
    def estimate(log):
        _, dip = field_at_rest(log)
        noise = replace(FixedWingNoise(), declination_rad=0.0, inclination_rad=dip)
        no_airspeed = ImuLog(log.t, log.gyro, log.accel, log.mag, np.full(len(log), np.nan))
        return estimate_fixedwing_attitude(no_airspeed, noise, factory).x[:, :4]
    return estimate


def _arrays(log):
    """The sample period and the three streams as VQF and ahrs read them: their step ``k`` turns by
    ``gyr[k]`` first and then uses ``acc[k]``, so their ``gyr[k]`` is the rate over the interval that
    ends at ``t[k]`` — the ImuLog's ``gyro[k − 1]`` (the first row repeats: nothing precedes it)."""
    rates_before = np.vstack([log.gyro[:1], log.gyro[:-1]])
    return (float(np.median(log.dt)),) + tuple(np.ascontiguousarray(a, dtype=float)
                                               for a in (rates_before, log.accel, log.mag))


def _vqf(kind):
    def estimate(log):
        import vqf

        Ts, gyr, acc, mag = _arrays(log)
        if kind == "offline VQF":
            q = vqf.offlineVQF(gyr, acc, mag, Ts)["quat9D"]
        else:
            q = getattr(vqf, kind)(Ts).updateBatch(gyr, acc, mag)["quat9D"]
        return quat_multiply(ENU_TO_NED, q)
    return estimate


def _ahrs(kind):
    def estimate(log):
        from ahrs.filters import Madgwick, Mahony

        Ts, gyr, acc, mag = _arrays(log)
        if kind == "Madgwick":
            return quat_multiply(NWU_TO_NED, Madgwick(gyr=gyr, acc=acc, mag=mag, frequency=1 / Ts).Q)
        return quat_multiply(ENU_TO_NED, Mahony(gyr=gyr, acc=acc, mag=mag, frequency=1 / Ts).Q)
    return estimate


_ESTIMATORS = {
    "quadlib MEKF": lambda log: estimate_orientation(log).q,
    "quadlib MEKF smoother": lambda log: estimate_orientation(log, offline=True).q,
    **{f"Kesten {name}": _kesten(name) for name in FILTERS},
    "Salmony EKF": _fixedwing(salmony_ekf),
    "fixed-wing ES-UKF": _fixedwing(error_state_ukf),
    "VQF": _vqf("VQF"),
    "BasicVQF": _vqf("BasicVQF"),
    "offline VQF": _vqf("offline VQF"),
    "ahrs Madgwick": _ahrs("Madgwick"),
    "ahrs Mahony": _ahrs("Mahony"),
}


def estimator_names() -> list[str]:
    """The names :func:`orientation_estimate` knows, quadlib's first."""
    return list(_ESTIMATORS)


def orientation_estimate(name: str, log: ImuLog) -> np.ndarray:
    """``q_nb`` (N, 4), sensor → NED, of the estimator ``name`` over ``log`` (with a magnetometer)."""
    if name not in _ESTIMATORS:
        raise ValueError(f"name: expected one of {estimator_names()}, got {name!r}")
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    if log.mag is None:
        raise ValueError("log.mag: expected magnetometer samples, got None")
    return _ESTIMATORS[name](log)


def score_estimators(names, log: ImuLog, q_truth, movement=None) -> tuple[dict, dict]:
    """Each estimator's BROAD errors over ``log`` (:func:`~quadlib.analysis.broad_errors`) and its
    cost, ``us_per_sample`` [µs] (wall-clock time of the whole call over the samples); and its
    estimates, ``q_nb`` (N, 4) per name."""
    rows, estimates = {}, {}
    for name in names:
        start = time.perf_counter()
        q = orientation_estimate(name, log)
        cost = (time.perf_counter() - start) / len(log) * 1e6
        rows[name] = broad_errors(q, q_truth, movement) | {"us_per_sample": cost}
        estimates[name] = q
    return rows, estimates


def error_components(q_estimate, q_truth) -> tuple[np.ndarray, np.ndarray]:
    """Heading and inclination error [deg] per sample, BROAD's split (see
    :func:`~quadlib.analysis.broad_errors`): the heading error signed (a turn about down, east of
    the truth positive), the inclination error its size; NaN where the truth is."""
    q_est = np.asarray(q_estimate, dtype=float)
    q_true = np.asarray(q_truth, dtype=float)
    if q_est.shape != q_true.shape or q_est.ndim != 2 or q_est.shape[1] != 4:
        raise ValueError(f"q_estimate, q_truth: expected the same (N, 4) shape, got {q_est.shape} and {q_true.shape}")
    missing = np.isnan(q_true).any(axis=1)
    e = quat_multiply(q_est, quat_conjugate(np.where(missing[:, None], [1.0, 0.0, 0.0, 0.0], q_true)))
    e = e * np.where(e[:, :1] < 0.0, -1.0, 1.0)
    heading = np.degrees(2.0 * np.arctan2(e[:, 3], e[:, 0]))
    inclination = np.degrees(2.0 * np.arccos(np.clip(np.hypot(e[:, 0], e[:, 3]), 0.0, 1.0)))
    heading[missing] = inclination[missing] = np.nan
    return heading, inclination
