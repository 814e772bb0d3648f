"""One quaternion at a time, unchecked: the inner steps of the attitude filters.

:mod:`quadlib.geometry.quaternion` checks every argument and works on stacks; a filter that has
validated its whole log calls these instead, once per sample, on one ``(4,)`` quaternion and
``(3,)`` vectors of floats. They compute the same as their checked namesakes (tested to 1e-15);
with Python floats instead of numpy's element-wise operations on 4 numbers, and without the
checks, they cost about a tenth as much. No argument is checked here: give them finite float
arrays of the right length.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["body_vector_jacobian", "conjugate", "dcm", "euler_dcm", "exp_rotvec", "from_dcm", "from_euler",
           "multiply", "normalize", "rate_matrix", "rotvec", "skew", "to_euler"]


def multiply(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``p ⊗ q`` (:func:`~quadlib.geometry.quaternion.quat_multiply`)."""
    pw, px, py, pz = p.tolist()
    qw, qx, qy, qz = q.tolist()
    return np.array([pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw])


def exp_rotvec(v: np.ndarray) -> np.ndarray:
    """The quaternion of the rotation vector ``v`` (:func:`~quadlib.geometry.quaternion.quat_from_rotvec`)."""
    x, y, z = v.tolist()
    angle = math.sqrt(x * x + y * y + z * z)
    half_sinc = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    return np.array([math.cos(0.5 * angle), half_sinc * x, half_sinc * y, half_sinc * z])


def rotvec(q: np.ndarray) -> np.ndarray:
    """The rotation vector of a unit ``q``, angle in [0, π] (:func:`~quadlib.geometry.quaternion.quat_to_rotvec`)."""
    w, x, y, z = q.tolist()
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    angle = 2.0 * math.atan2(s, w)
    scale = angle / s if s > 1e-8 else 2.0 + angle * angle / 12.0
    return np.array([scale * x, scale * y, scale * z])


def conjugate(q: np.ndarray) -> np.ndarray:
    """``q*``, the inverse rotation of a unit ``q`` (:func:`~quadlib.geometry.quaternion.quat_conjugate`)."""
    w, x, y, z = q.tolist()
    return np.array([w, -x, -y, -z])


def dcm(q: np.ndarray) -> np.ndarray:
    """``R(q)`` as the homogeneous quadratic in ``q`` (equal to
    :func:`~quadlib.geometry.quaternion.quat_to_dcm` for a unit ``q``)."""
    w, x, y, z = q.tolist()
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    return np.array([[ww + xx - yy - zz, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), ww - xx + yy - zz, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), ww - xx - yy + zz]])


def euler_dcm(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """``R_nb = R_z(ψ) R_y(θ) R_x(φ)`` of three Z-Y-X Euler angles [rad]
    (:func:`~quadlib.geometry.rotations.euler_to_dcm`)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy],
                     [cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy],
                     [-sp, cp * sr, cp * cr]])


def from_euler(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """``q_nb`` of three Z-Y-X Euler angles [rad] (:func:`~quadlib.geometry.quaternion.quat_from_euler`)."""
    cr, sr, cp, sp = math.cos(0.5 * roll), math.sin(0.5 * roll), math.cos(0.5 * pitch), math.sin(0.5 * pitch)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


def to_euler(q: np.ndarray) -> tuple[float, float, float]:
    """Z-Y-X Euler angles ``(roll, pitch, yaw)`` [rad] of a unit ``q``, with the same choice at
    gimbal lock (roll = 0) as :func:`~quadlib.geometry.quaternion.quat_to_euler`."""
    w, x, y, z = q.tolist()
    sin_pitch = min(1.0, max(-1.0, 2.0 * (w * y - x * z)))
    if abs(sin_pitch) > 1.0 - 1e-12:
        side = math.copysign(1.0, sin_pitch)
        return 0.0, side * math.pi / 2, -side * 2.0 * math.atan2(x, w)
    return (math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)), math.asin(sin_pitch),
            math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


def from_dcm(R: np.ndarray) -> np.ndarray:
    """The unit quaternion (``w ≥ 0``) of a rotation matrix, Shepperd's method: divide by the largest
    of ``4w², 4x², 4y², 4z²`` (:func:`~quadlib.geometry.quaternion.quat_from_dcm`)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
    tr = r00 + r11 + r22
    squares = (1.0 + tr, 1.0 + 2.0 * r00 - tr, 1.0 + 2.0 * r11 - tr, 1.0 + 2.0 * r22 - tr)
    big = max(range(4), key=squares.__getitem__)
    rows = ((squares[0], r21 - r12, r02 - r20, r10 - r01), (r21 - r12, squares[1], r01 + r10, r02 + r20),
            (r02 - r20, r01 + r10, squares[2], r12 + r21), (r10 - r01, r02 + r20, r12 + r21, squares[3]))
    q = np.array(rows[big]) / (2.0 * math.sqrt(squares[big]))
    q = q / math.sqrt(float(q @ q))
    return q if q[0] >= 0.0 else -q


def skew(v: np.ndarray) -> np.ndarray:
    """``[v]×``, the matrix of the cross product: ``[v]× w = v × w``."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def normalize(q: np.ndarray) -> np.ndarray:
    """``q / |q|`` for a quaternion that is not zero."""
    return q / math.sqrt(float(q @ q))


def rate_matrix(q: np.ndarray) -> np.ndarray:
    """``Ξ(q)``, ``(4, 3)``: ``q ⊗ [0, ω] = Ξ(q) ω``
    (:func:`~quadlib.attitude.bias_model.quaternion_rate_matrix`)."""
    q0, q1, q2, q3 = q.tolist()
    return np.array([[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]])


def body_vector_jacobian(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``∂(R(q)ᵀ v)/∂q``, ``(3, 4)`` (:func:`~quadlib.geometry.quaternion.vector_jacobian`). With
    ``q = [w, r]``, ``R(q)ᵀ v = (w² − r·r) v + 2 (r·v) r − 2 w (r × v)``, so
    ``∂/∂w = 2 (w v − r × v)`` and ``∂/∂r = 2 ((r·v) I + r vᵀ − v rᵀ + w [v]×)``."""
    w, x, y, z = q.tolist()
    vx, vy, vz = v.tolist()
    rv = x * vx + y * vy + z * vz
    return 2.0 * np.array([
        [w * vx - (y * vz - z * vy), rv, x * vy - vx * y - w * vz, x * vz - vx * z + w * vy],
        [w * vy - (z * vx - x * vz), y * vx - vy * x + w * vz, rv, y * vz - vy * z - w * vx],
        [w * vz - (x * vy - y * vx), z * vx - vz * x - w * vy, z * vy - vz * y + w * vx, rv]])
