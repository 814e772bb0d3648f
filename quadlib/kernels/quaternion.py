"""One quaternion at a time, unchecked, compiled: the inner steps of every attitude filter.

:mod:`quadlib.geometry.quaternion` checks every argument and works on stacks; a filter that has
validated its whole log calls these instead, once per sample, on one ``(4,)`` quaternion and
``(3,)`` vectors of floats. They compute the same as their checked namesakes (tested to 1e-15).
numba compiles them, so the readable filters call them from Python and the compiled loops
(:mod:`quadlib.engine`, the models' kernels of :mod:`quadlib.kernels` …) from inside: one
implementation. No argument is checked here: give them finite float arrays of the right length
(C-contiguous and writable, or numba compiles another version for the layout).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["body_vector_jacobian", "conjugate", "dcm", "dcm_entries", "euler_dcm", "exp_rotvec", "from_dcm",
           "from_euler", "matrix", "multiply", "normalize", "rate_entries", "rate_matrix",
           "rotvec", "skew", "skew_entries", "to_euler"]


@njit(cache=True)
def multiply(p, q):
    """``p ⊗ q`` (:func:`~quadlib.geometry.quaternion.quat_multiply`)."""
    return np.array([p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3],
                     p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2],
                     p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1],
                     p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0]])


@njit(cache=True)
def exp_rotvec(v):
    """The quaternion of the rotation vector ``v`` (:func:`~quadlib.geometry.quaternion.quat_from_rotvec`)."""
    angle = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    half_sinc = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    return np.array([math.cos(0.5 * angle), half_sinc * v[0], half_sinc * v[1], half_sinc * v[2]])


@njit(cache=True)
def rotvec(q):
    """The rotation vector of a unit ``q``, angle in [0, π] (:func:`~quadlib.geometry.quaternion.quat_to_rotvec`)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    angle = 2.0 * math.atan2(s, w)
    scale = angle / s if s > 1e-8 else 2.0 + angle * angle / 12.0
    return np.array([scale * x, scale * y, scale * z])


@njit(cache=True)
def conjugate(q):
    """``q*``, the inverse rotation of a unit ``q`` (:func:`~quadlib.geometry.quaternion.quat_conjugate`)."""
    return np.array([q[0], -q[1], -q[2], -q[3]])


@njit(cache=True)
def matrix(rows, cols, values):
    """A ``(rows, cols)`` array from a flat tuple of ``values``, row by row: numba builds one from
    nested lists about five times slower than the arithmetic that fills a 3 × 3 rotation."""
    out = np.empty((rows, cols))
    for i in range(rows):
        for j in range(cols):
            out[i, j] = values[i * cols + j]
    return out


@njit(cache=True)
def dcm_entries(q):
    """The nine entries of :func:`dcm` row by row, as a tuple (``R[i, j]`` is entry ``3 i + j``): a
    kernel that reads a few of them makes no array."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    return (ww + xx - yy - zz, 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), ww - xx + yy - zz, 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), ww - xx - yy + zz)


@njit(cache=True)
def dcm(q):
    """``R(q)`` as the homogeneous quadratic in ``q`` (equal to
    :func:`~quadlib.geometry.quaternion.quat_to_dcm` for a unit ``q``)."""
    return matrix(3, 3, dcm_entries(q))


@njit(cache=True)
def euler_dcm(roll, pitch, yaw):
    """``R_nb = R_z(ψ) R_y(θ) R_x(φ)`` of three Z-Y-X Euler angles [rad]
    (:func:`~quadlib.geometry.rotations.euler_to_dcm`)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return matrix(3, 3, (cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy,
                         cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy,
                         -sp, cp * sr, cp * cr))


@njit(cache=True)
def from_euler(roll, pitch, yaw):
    """``q_nb`` of three Z-Y-X Euler angles [rad] (:func:`~quadlib.geometry.quaternion.quat_from_euler`)."""
    cr, sr, cp, sp = math.cos(0.5 * roll), math.sin(0.5 * roll), math.cos(0.5 * pitch), math.sin(0.5 * pitch)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    return np.array([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


@njit(cache=True)
def to_euler(q):
    """Z-Y-X Euler angles ``(roll, pitch, yaw)`` [rad] of a unit ``q``, with the same choice at
    gimbal lock (roll = 0) as :func:`~quadlib.geometry.quaternion.quat_to_euler`."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    sin_pitch = min(1.0, max(-1.0, 2.0 * (w * y - x * z)))
    if abs(sin_pitch) > 1.0 - 1e-12:
        side = math.copysign(1.0, sin_pitch)
        return 0.0, side * math.pi / 2, -side * 2.0 * math.atan2(x, w)
    return (math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)), math.asin(sin_pitch),
            math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))


@njit(cache=True)
def from_dcm(R):
    """The unit quaternion (``w ≥ 0``) of a rotation matrix, Shepperd's method: divide by the largest
    of ``4w², 4x², 4y², 4z²`` (:func:`~quadlib.geometry.quaternion.quat_from_dcm`)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    squares = np.array([1.0 + tr, 1.0 + 2.0 * R[0, 0] - tr, 1.0 + 2.0 * R[1, 1] - tr, 1.0 + 2.0 * R[2, 2] - tr])
    big = int(np.argmax(squares))  # the first of equal ones, as max() picks it
    d21, d02, d10 = R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]
    s01, s02, s12 = R[0, 1] + R[1, 0], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1]
    if big == 0:
        q = np.array([squares[0], d21, d02, d10])
    elif big == 1:
        q = np.array([d21, squares[1], s01, s02])
    elif big == 2:
        q = np.array([d02, s01, squares[2], s12])
    else:
        q = np.array([d10, s02, s12, squares[3]])
    q = q / (2.0 * math.sqrt(squares[big]))
    q = q / math.sqrt(q @ q)
    return q if q[0] >= 0.0 else -q


@njit(cache=True)
def skew_entries(v):
    """The nine entries of :func:`skew` row by row, as a tuple (``[v]×[i, j]`` is entry ``3 i + j``)."""
    return (0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0)


@njit(cache=True)
def skew(v):
    """``[v]×``, the matrix of the cross product: ``[v]× w = v × w``."""
    return matrix(3, 3, skew_entries(v))


@njit(cache=True)
def normalize(q):
    """``q / |q|`` for a quaternion that is not zero."""
    return q / math.sqrt(q @ q)


@njit(cache=True)
def rate_entries(q):
    """The twelve entries of :func:`rate_matrix` row by row, as a tuple (``Ξ[i, j]`` is entry ``3 i + j``)."""
    return (-q[1], -q[2], -q[3], q[0], -q[3], q[2], q[3], q[0], -q[1], -q[2], q[1], q[0])


@njit(cache=True)
def rate_matrix(q):
    """``Ξ(q)``, ``(4, 3)``: ``q ⊗ [0, ω] = Ξ(q) ω``
    (:func:`~quadlib.attitude.bias_model.quaternion_rate_matrix`)."""
    return matrix(4, 3, rate_entries(q))


@njit(cache=True)
def body_vector_jacobian(q, v):
    """``∂(R(q)ᵀ v)/∂q``, ``(3, 4)`` (:func:`~quadlib.geometry.quaternion.vector_jacobian`), as its
    twelve entries row by row in a tuple (entry ``4 i + j``; a kernel writes them where it needs them).
    With ``q = [w, r]``, ``R(q)ᵀ v = (w² − r·r) v + 2 (r·v) r − 2 w (r × v)``, so
    ``∂/∂w = 2 (w v − r × v)`` and ``∂/∂r = 2 ((r·v) I + r vᵀ − v rᵀ + w [v]×)``."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    vx, vy, vz = v[0], v[1], v[2]
    rv = x * vx + y * vy + z * vz
    return (2.0 * (w * vx - (y * vz - z * vy)), 2.0 * rv, 2.0 * (x * vy - vx * y - w * vz),
            2.0 * (x * vz - vx * z + w * vy), 2.0 * (w * vy - (z * vx - x * vz)), 2.0 * (y * vx - vy * x + w * vz),
            2.0 * rv, 2.0 * (y * vz - vy * z - w * vx), 2.0 * (w * vz - (x * vy - y * vx)),
            2.0 * (z * vx - vz * x - w * vy), 2.0 * (z * vy - vz * y + w * vx), 2.0 * rv)
