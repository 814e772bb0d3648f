"""Attitude from accelerometer and magnetometer, and averages of attitudes (Kesten §2.2.1–2.2.2).

Conventions as everywhere in quadlib: ``q_nb`` scalar first, NED/FRD, and an accelerometer that
reads ``−g`` along the down axis at rest (``f_b ≈ −R_nbᵀ g_n``). Kesten's accelerometer vector
points *along* gravity, so his ``z_n^b = a/|a|`` (eq. 2.2) is ``−f_b/|f_b|`` here.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from quadlib.geometry.quaternion import (
    as_unit_quaternions,
    quat_canonical,
    quat_conjugate,
    quat_from_dcm,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_to_rotvec,
)
from quadlib.validation import as_finite_array, as_positive, as_vectors3

__all__ = ["AbsoluteAttitude", "attitude_from_accel_mag", "average_geodesic", "average_quaternion",
           "average_rotvec"]


class AbsoluteAttitude(NamedTuple):
    """Attitudes ``q_nb`` (N, 4) from accelerometer and magnetometer, and which samples are fresh.

    ``valid[k]`` is False where sample ``k`` could not give an attitude (free fall, or the two
    vectors nearly parallel); ``q_nb[k]`` then holds the last valid attitude (the identity before
    the first one).
    """

    q_nb: np.ndarray
    valid: np.ndarray


def attitude_from_accel_mag(f_b, m_b, min_accel_m_s2: float = 2.0, min_angle_rad: float = np.radians(10.0)
                            ) -> AbsoluteAttitude:
    """Kesten eqs. (2.2)–(2.5): the NED axes seen in the body frame, from gravity and the field.

    Down is ``−f_b/|f_b|``; north is the part of ``m_b`` perpendicular to down, normalised; east
    is down × north. The matrix with these columns is ``C_n^b = R_nbᵀ``.

    Parameters
    ----------
    f_b : (N, 3) specific force [m/s²], FRD
    m_b : (N, 3) magnetic field, any unit, FRD
    min_accel_m_s2 : float
        Below this ``|f_b|`` the sample is free fall and is not used (Kesten: "cannot be solved").
    min_angle_rad : float
        Below this angle between ``f_b`` and ``m_b`` (or above π minus it) north is undefined or
        badly conditioned, and the sample is not used.
    """
    f_b, m_b = as_finite_array("f_b", f_b, ndim=2), as_finite_array("m_b", m_b, ndim=2)
    if f_b.shape[1] != 3 or m_b.shape != f_b.shape:
        raise ValueError(f"f_b, m_b: expected two (N, 3) arrays, got {f_b.shape} and {m_b.shape}")
    min_accel, min_angle = as_positive("min_accel_m_s2", min_accel_m_s2), as_positive("min_angle_rad", min_angle_rad)
    f_norm, m_norm = np.linalg.norm(f_b, axis=1), np.linalg.norm(m_b, axis=1)
    down = -f_b / np.where(f_norm > 0, f_norm, 1.0)[:, None]
    north = m_b - np.sum(m_b * down, axis=1, keepdims=True) * down  # eq. (2.3): remove the down part
    n_norm = np.linalg.norm(north, axis=1)
    sin_angle = n_norm / np.where(m_norm > 0, m_norm, 1.0)
    valid = (f_norm >= min_accel) & (sin_angle >= np.sin(min_angle))
    north = north / np.where(n_norm > 0, n_norm, 1.0)[:, None]
    east = np.cross(down, north)  # eq. (2.4)
    C_nb = np.stack([north, east, down], axis=-1)  # eq. (2.5): columns are the NED axes in body coordinates
    q = np.tile([1.0, 0.0, 0.0, 0.0], (len(f_b), 1))
    if valid.any():
        q[valid] = quat_from_dcm(np.swapaxes(C_nb[valid], 1, 2))
    # hold the last valid attitude through invalid samples
    last = np.maximum.accumulate(np.where(valid, np.arange(len(valid)), -1))
    held = np.where(last[:, None] >= 0, q[np.clip(last, 0, None)], q)
    return AbsoluteAttitude(held, valid)


def _weights(w1, w2):
    w1, w2 = as_finite_array("w1", w1), as_finite_array("w2", w2)
    if np.any(w1 < 0) or np.any(w2 < 0) or np.any(w1 + w2 <= 0):
        raise ValueError(f"w1, w2: expected non-negative weights with a positive sum, got {w1.tolist()} and "
                         f"{w2.tolist()}")
    return w1, w2


def average_rotvec(theta1, theta2, w1=0.5, w2=0.5) -> np.ndarray:
    """Kesten eq. (2.10): weighted mean of two orientation vectors (exact only when they are parallel)."""
    w1, w2 = _weights(w1, w2)
    t1, t2 = as_vectors3("theta1", theta1), as_vectors3("theta2", theta2)
    return (w1[..., None] * t1 + w2[..., None] * t2) / (w1 + w2)[..., None]


def average_quaternion(q1, q2, w1=0.5, w2=0.5) -> np.ndarray:
    """Kesten eqs. (2.11)–(2.12): weighted mean of two quaternions as vectors, renormalised.

    The sign of ``q2`` matters (``q`` and ``−q`` are one attitude but average differently); it is
    used as given.
    """
    w1, w2 = _weights(w1, w2)
    q1, q2 = as_unit_quaternions("q1", q1), as_unit_quaternions("q2", q2)
    return quat_normalize(w1[..., None] * q1 + w2[..., None] * q2)


def average_geodesic(q1, q2, w1=0.5, w2=0.5) -> np.ndarray:
    """Kesten eqs. (2.13)–(2.16): the attitude on the shortest rotation from ``q1`` to ``q2``, a
    fraction ``w2/(w1 + w2)`` of the way — it minimises ``w1 θ1 + w2 θ2`` (eq. 2.9)."""
    w1, w2 = _weights(w1, w2)
    q1, q2 = as_unit_quaternions("q1", q1), as_unit_quaternions("q2", q2)
    theta_delta = quat_to_rotvec(quat_canonical(quat_multiply(quat_conjugate(q1), q2)))  # eqs. (2.14), shortest
    k = (w2 / (w1 + w2))[..., None]  # eq. (2.15)
    return quat_multiply(q1, quat_from_rotvec(k * theta_delta))  # eq. (2.16)
