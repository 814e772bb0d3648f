"""Where the orientation filter starts: the first attitude the accelerometer and magnetometer give."""

from __future__ import annotations

import numpy as np

from quadlib.attitude.lowpass import held_rows
from quadlib.geometry.quaternion import quat_multiply, quat_to_dcm
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog
from quadlib.kernels.quaternion import exp_rotvec, multiply

__all__: list[str] = []  # internal: orientation.py is the interface


def initial_attitude(log: ImuLog, declination_rad: float = 0.0) -> tuple[np.ndarray, bool]:
    """``(q_nb, heading)``: where the filter starts, and whether a magnetometer reading gave its heading.

    From the first sample with an accelerometer and a magnetometer reading that give an attitude
    (:func:`~quadlib.geometry.attitude_from_accel_mag`), turned about the down axis by the
    declination so that yaw is from true north. When the field's first such reading comes after
    the first accelerometer reading, the start takes its tilt from that first accelerometer reading
    and its heading from the field read later, turned back through the gyro
    (:func:`carried_back`): the sensor may have turned in between. Without a magnetometer reading that does
    (none at all, all NaN, or every one along gravity), from the first accelerometer reading
    alone, with body x (or y, when x points along gravity) starting north: any mounting, upside
    down included; ``heading`` is then False.
    """
    accel_ok = np.isfinite(log.accel).all(axis=1) & (np.linalg.norm(np.nan_to_num(log.accel), axis=1) > 2.0)
    if not accel_ok.any():
        raise ValueError("log.accel: expected at least one finite reading of the specific force, got none")
    turn = np.array([np.cos(declination_rad / 2), 0.0, 0.0, np.sin(declination_rad / 2)])
    k0 = int(np.argmax(accel_ok))
    if log.mag is not None:
        rows = np.flatnonzero(accel_ok & np.isfinite(log.mag).all(axis=1))
        for chunk in range(0, rows.size, 1000):
            k = rows[chunk:chunk + 1000]
            start = attitude_from_accel_mag(log.accel[k], log.mag[k])
            if start.valid.any():
                k1 = int(k[np.argmax(start.valid)])
                q_magnetic = start.q_nb[int(np.argmax(start.valid))]
                if k1 > k0:  # a later first reading: the tilt of the first sample, the heading carried back to it
                    back = attitude_from_accel_mag(log.accel[k0][None], carried_back(log, k0, k1)[None])
                    q_magnetic = back.q_nb[0] if back.valid[0] else q_magnetic
                return quat_multiply(turn, q_magnetic), True
    f = log.accel[k0]
    # tilt only: a "field" along body x (or y) fixes the unobservable yaw
    axis = np.eye(3)[0 if abs(f[0]) < 0.9 * np.linalg.norm(f) else 1]
    return attitude_from_accel_mag(f[None], axis[None]).q_nb[0], False


def carried_back(log: ImuLog, k0: int, k1: int) -> np.ndarray:
    """The field read at row ``k1`` as the body at row ``k0`` saw it: turned back through the gyro
    (a missing row turning as the one before it), so that a first reading taken while the sensor
    turns gives the heading of the first sample, not its own."""
    gyro, q = held_rows(log.gyro), np.array([1.0, 0.0, 0.0, 0.0])  # the body at k relative to the body at k0
    for k in range(k0, k1):
        q = multiply(q, exp_rotvec(gyro[k] * (log.t[k + 1] - log.t[k])))
    return quat_to_dcm(q) @ log.mag[k1]
