"""Sensor faults injected into an IMU log: what the fault matrix and the recovery tests feed every
attitude estimator (``benchmarks/faults.py``, ``tests/test_fault_recovery.py``).

Each fault starts at ``start_s`` and, unless it lasts to the end of the log, ends ``length_s``
later; the result maps a fault's name to the faulty log and the time the fault ends, from which
an estimator's recovery is measured.
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import G0
from quadlib.imu import ImuLog
from quadlib.validation import as_finite_number, as_instance, as_positive, as_rng, as_vector

__all__ = ["imu_faults"]


def imu_faults(log: ImuLog, field_n, accel_sigma_m_s2: float, rng, start_s: float = 10.0,
               length_s: float = 2.0) -> dict[str, tuple[ImuLog, float]]:
    """``{name: (faulty log, end of the fault [s])}`` for seven accelerometer and magnetometer faults.

    * a magnet fixed to the body, adding 5× and 20× the field's strength along body x;
    * a stuck magnetometer (the first sample of the window repeated) and 30 % magnetometer
      dropouts (NaN rows, to the end of the log);
    * 2 s of free fall (the accelerometer reads noise around zero);
    * a 30 g shock for 50 ms, clipped at a 16 g full scale;
    * 2 % accelerometer spikes of 20 σ (to the end of the log).

    ``field_n`` is the Earth's field in the magnetometer's unit; ``log.mag`` must be present.
    """
    log = as_instance("log", log, ImuLog)
    if log.mag is None:
        raise ValueError("log.mag: expected magnetometer samples, got None")
    field = as_vector("field_n", field_n, 3)
    sigma = as_positive("accel_sigma_m_s2", accel_sigma_m_s2)
    rng = as_rng(rng)
    start, length = as_finite_number("start_s", start_s), as_positive("length_s", length_s)
    t = log.t
    window = (t >= start) & (t < start + length)
    if not window.any():
        raise ValueError(f"start_s: expected a window inside the log [{t[0]:g}, {t[-1]:g}] s, got {start:g} s")

    def faulty(accel=None, mag=None):
        return ImuLog(t, log.gyro, log.accel if accel is None else accel, log.mag if mag is None else mag,
                      log.airspeed)

    out = {}
    for factor in (5.0, 20.0):
        mag = np.array(log.mag)
        mag[window] += factor * np.linalg.norm(field) * np.array([1.0, 0.0, 0.0])
        out[f"magnetometer + {factor:.0f}x field (magnet)"] = (faulty(mag=mag), start + length)
    mag = np.array(log.mag)
    present = window & ~np.isnan(mag[:, 0])
    mag[present] = mag[np.flatnonzero(present)[0]]
    out["stuck magnetometer"] = (faulty(mag=mag), start + length)
    mag = np.array(log.mag)
    mag[rng.random(t.size) < 0.3] = np.nan
    out["magnetometer 30 % dropouts"] = (faulty(mag=mag), float(t[-1]))
    accel = np.array(log.accel)
    accel[window] = rng.normal(0.0, sigma, (window.sum(), 3))
    out["free fall 2 s"] = (faulty(accel=accel), start + length)
    accel = np.array(log.accel)
    shock = (t >= start) & (t < start + 0.05)
    accel[shock] = np.clip(accel[shock] + [0.0, 30 * G0, 0.0], -16 * G0, 16 * G0)
    out["30 g shock clipped at 16 g"] = (faulty(accel=accel), start + 0.05)
    accel = np.array(log.accel)
    hit = rng.random(t.size) < 0.02
    accel[hit] += rng.normal(0.0, 20 * sigma, (hit.sum(), 3))
    out["accelerometer spikes 20σ (2 %)"] = (faulty(accel=accel), float(t[-1]))
    return out
