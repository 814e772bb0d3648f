"""Unit quaternions, scalar first ``[w, x, y, z]``, Hamilton product.

``q_nb`` rotates body (FRD) vectors into NED: ``v_n = R(q_nb) v_b``. Every function accepts
stacks: a ``(..., 4)`` array of quaternions (and ``(..., 3)`` of vectors) is processed row by
row without a Python loop. ``q`` and ``-q`` are the same rotation; :func:`quat_canonical`
picks the one with ``w >= 0`` for comparisons.

Source: Kesten (2010) §1.1 (product, eq. 1.4; rotation, eq. 1.11; rotation vector, eq. 1.8);
Tellex et al. §7.1.2 (eq. 43, integrating body rates).
"""

from __future__ import annotations

import numpy as np

from quadlib.validation import as_finite_array, as_positive, as_quaternions, as_vector, as_vectors3

__all__ = ["UNIT_TOLERANCE", "as_unit_quaternions", "body_rates_between", "body_vector",
           "integrate_body_rate", "integrate_body_rate_linear", "quat_canonical", "quat_conjugate",
           "quat_from_dcm", "quat_from_euler", "quat_from_rotvec", "quat_multiply", "quat_normalize",
           "quat_rotate", "quat_to_dcm", "quat_to_euler", "quat_to_rotvec", "vector_jacobian"]


def quat_multiply(p, q) -> np.ndarray:
    """Hamilton product ``p ⊗ q`` (Kesten eq. 1.4): first rotate by ``q``, then by ``p``."""
    p, q = as_quaternions("p", p), as_quaternions("q", q)
    pw, px, py, pz = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    qw, qx, qy, qz = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    out = np.empty(np.broadcast_shapes(p.shape, q.shape))
    out[..., 0] = pw * qw - px * qx - py * qy - pz * qz
    out[..., 1] = pw * qx + px * qw + py * qz - pz * qy
    out[..., 2] = pw * qy - px * qz + py * qw + pz * qx
    out[..., 3] = pw * qz + px * qy - py * qx + pz * qw
    return out


def quat_conjugate(q) -> np.ndarray:
    """``[w, -x, -y, -z]``: the inverse rotation of a unit quaternion."""
    return as_quaternions("q", q) * np.array([1.0, -1.0, -1.0, -1.0])


UNIT_TOLERANCE = 1e-6
"""How far ``|q|`` may be from 1 where a unit quaternion is required."""


def quat_normalize(q) -> np.ndarray:
    """Scale to unit norm; a zero quaternion is refused. Safe for any finite magnitude."""
    q = as_quaternions("q", q)
    with np.errstate(over="ignore", under="ignore"):
        norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if not (np.all(np.isfinite(norm)) and np.all(norm > 1e-150)):  # squares over- or underflowed
        q = q / np.max(np.abs(q), axis=-1, keepdims=True).clip(min=np.finfo(float).tiny)
        norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if np.any(norm < 1e-12):
        raise ValueError("q: expected non-zero quaternions, got one with norm 0")
    return q / norm


def as_unit_quaternions(name: str, q, tolerance: float | None = UNIT_TOLERANCE) -> np.ndarray:
    """``q`` as a finite ``(..., 4)`` array, refused (naming ``name``) if any is further than
    ``tolerance`` from unit norm (None: any norm)."""
    q = as_quaternions(name, q)
    if tolerance is not None:
        off = np.abs(np.sum(q * q, axis=-1) - 1.0)
        if np.any(off > 2 * tolerance):
            norm = float(np.sqrt(np.sum(q * q, axis=-1)).reshape(-1)[np.argmax(off.reshape(-1))])
            raise ValueError(f"{name}: expected unit quaternions (|norm − 1| ≤ {tolerance:g}), got norm {norm:.6g};"
                             " normalise first (quat_normalize)")
    return q


def _nonzero(name: str, q) -> np.ndarray:
    """``q`` as quaternions, none of them zero."""
    q = as_quaternions(name, q)
    if not np.all(np.any(q != 0.0, axis=-1)):
        raise ValueError(f"{name}: expected non-zero quaternions, got one that is all zeros")
    return q


def quat_canonical(q) -> np.ndarray:
    """The representative with ``w >= 0`` of ``±q`` (the same rotation)."""
    q = as_quaternions("q", q)
    return np.where(q[..., :1] < 0.0, -q, q)


def quat_from_rotvec(v) -> np.ndarray:
    """Quaternion of the rotation by angle ``|v|`` about ``v / |v|`` (Kesten eq. 1.8)."""
    v = as_vectors3("v", v)
    angle = np.sqrt(np.sum(v * v, axis=-1))
    # sin(a/2)/a, with its Taylor series where a is tiny
    half_sinc = np.where(angle > 1e-8, np.sin(0.5 * angle) / np.where(angle > 1e-8, angle, 1.0), 0.5 - angle**2 / 48.0)
    out = np.empty(v.shape[:-1] + (4,))
    out[..., 0] = np.cos(0.5 * angle)
    out[..., 1:] = half_sinc[..., None] * v
    return out


def quat_to_rotvec(q) -> np.ndarray:
    """Rotation vector (axis × angle, angle in [0, π]) of unit ``q``; inverse of :func:`quat_from_rotvec`.
    Refuses quaternions further than ``UNIT_TOLERANCE`` from unit norm."""
    q = quat_canonical(as_unit_quaternions("q", q, UNIT_TOLERANCE))
    v = q[..., 1:]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(s, q[..., :1])
    # angle / sin(angle/2), with its Taylor series where the angle is tiny
    scale = np.where(s > 1e-8, angle / np.where(s > 1e-8, s, 1.0), 2.0 + angle**2 / 12.0)
    return scale * v


def quat_to_dcm(q, unit_tolerance: float | None = UNIT_TOLERANCE) -> np.ndarray:
    """Rotation matrix ``R(q)``, ``(..., 3, 3)``, for unit ``q`` (``v' = R v``).

    A quaternion further than ``unit_tolerance`` from unit norm is refused (the formula would
    return a matrix that is not a rotation — the identity for ``q = 0``). ``None`` evaluates the
    quadratic polynomial anywhere, for exact derivatives by central differences.
    """
    q = as_unit_quaternions("q", q, unit_tolerance)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    R = np.empty(q.shape[:-1] + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    R[..., 2, 0], R[..., 2, 1], R[..., 2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    return R


def quat_from_dcm(R) -> np.ndarray:
    """Unit quaternion (``w >= 0``) of rotation matrices ``(..., 3, 3)``.

    Uses the largest of ``w, x, y, z`` to divide by (Shepperd's method), so it is accurate for
    every rotation, including 180° turns where ``w = 0``.
    """
    R = as_finite_array("R", R)
    if R.ndim < 2 or R.shape[-2:] != (3, 3):
        raise ValueError(f"R: expected shape (..., 3, 3), got {R.shape}")
    r = R.reshape(-1, 3, 3)
    off = np.abs(np.einsum("nji,njk->nik", r, r) - np.eye(3)).max(axis=(1, 2))
    det = np.linalg.det(r)
    if np.any(off > 1e-6) or np.any(det <= 0):
        k = int(np.argmax(np.maximum(off, -det)))
        raise ValueError(f"R: expected rotation matrices (orthonormal, determinant +1), got max |RᵀR − I| = "
                         f"{off[k]:.3g} and determinant {det[k]:.3g}" + (" (a reflection)" if det[k] < 0 else ""))
    tr = np.trace(r, axis1=1, axis2=2)
    # 4 w², 4 x², 4 y², 4 z², each from the trace and one diagonal element
    squares = np.column_stack([1 + tr, 1 + 2 * r[:, 0, 0] - tr, 1 + 2 * r[:, 1, 1] - tr, 1 + 2 * r[:, 2, 2] - tr])
    big = np.argmax(squares, axis=1)
    # each row: the four products 4·(largest)·(component), from the off-diagonal sums and differences
    w4 = np.column_stack([squares[:, 0], r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]])
    x4 = np.column_stack([r[:, 2, 1] - r[:, 1, 2], squares[:, 1], r[:, 0, 1] + r[:, 1, 0], r[:, 0, 2] + r[:, 2, 0]])
    y4 = np.column_stack([r[:, 0, 2] - r[:, 2, 0], r[:, 0, 1] + r[:, 1, 0], squares[:, 2], r[:, 1, 2] + r[:, 2, 1]])
    z4 = np.column_stack([r[:, 1, 0] - r[:, 0, 1], r[:, 0, 2] + r[:, 2, 0], r[:, 1, 2] + r[:, 2, 1], squares[:, 3]])
    rows = np.stack([w4, x4, y4, z4], axis=1)[np.arange(len(r)), big]
    q = rows / (2.0 * np.sqrt(squares[np.arange(len(r)), big]))[:, None]
    return quat_canonical(quat_normalize(q)).reshape(R.shape[:-2] + (4,))


def quat_rotate(q, v) -> np.ndarray:
    """Rotate vectors: ``R(q) v`` (Kesten eq. 1.11, ``q ⊗ [0, v] ⊗ q*``)."""
    return np.einsum("...ij,...j->...i", quat_to_dcm(q), as_vectors3("v", v))


def quat_from_euler(roll, pitch, yaw) -> np.ndarray:
    """``q_nb`` of Z-Y-X Euler angles [rad]: yaw ψ, then pitch θ, then roll φ."""
    hr, hp, hy = (0.5 * as_finite_array(name, a) for name, a in (("roll", roll), ("pitch", pitch), ("yaw", yaw)))
    cr, sr, cp, sp, cy, sy = np.cos(hr), np.sin(hr), np.cos(hp), np.sin(hp), np.cos(hy), np.sin(hy)
    return np.stack([cr * cp * cy + sr * sp * sy,
                     sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy], axis=-1)


def quat_to_euler(q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Z-Y-X Euler angles ``(roll, pitch, yaw)`` [rad] of unit ``q``; pitch in [-π/2, π/2].

    At pitch ±90° (gimbal lock) roll and yaw are not separable; the yaw returned is then the
    combination that reproduces the rotation with roll = 0.
    """
    w, x, y, z = np.moveaxis(as_unit_quaternions("q", q, UNIT_TOLERANCE), -1, 0)
    sin_pitch = np.clip(2.0 * (w * y - x * z), -1.0, 1.0)
    roll = np.arctan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    locked = np.abs(sin_pitch) > 1.0 - 1e-12
    roll = np.where(locked, 0.0, roll)
    yaw = np.where(locked, -np.sign(sin_pitch) * 2.0 * np.arctan2(x, w), yaw)
    pitch = np.where(locked, np.sign(sin_pitch) * np.pi / 2, np.arcsin(sin_pitch))
    return roll, pitch, yaw


def integrate_body_rate_linear(q, omega_b, dt: float) -> np.ndarray:
    """Kesten eq. (2.8): ``q ⊗ [1, ½ ω Δt]``, the first-order version of eq. (2.7).

    Not a unit quaternion: its norm grows by ``√(1 + |ω Δt|²/4)`` per step, so filters using it
    renormalise.
    """
    omega = as_vectors3("omega_b", omega_b) * (0.5 * as_positive("dt", dt))
    return quat_multiply(_nonzero("q", q), np.concatenate([np.ones(omega.shape[:-1] + (1,)), omega], axis=-1))


def integrate_body_rate(q, omega_b, dt: float) -> np.ndarray:
    """Attitude after turning at constant body rate ``omega_b`` [rad/s] for ``dt`` [s].

    .. math:: q_{k+1} = q_k \\otimes \\exp\\left(\\tfrac12 \\omega_b \\Delta t\\right)

    Kesten eq. (2.7). Body rates multiply on the *right* of ``q_nb``. Differs from the source: Tellex eq. (43)
    multiplies on the left, as in Diebel's convention where the quaternion maps global to body.
    """
    return quat_multiply(_nonzero("q", q), quat_from_rotvec(as_vectors3("omega_b", omega_b) * as_positive("dt", dt)))


def body_rates_between(q_nb, dt: float) -> np.ndarray:
    """Body rates ``(N, 3)`` [rad/s] that turn each attitude of ``q_nb`` ``(N, 4)`` into the next in
    ``dt`` [s] at a constant rate (the inverse of :func:`integrate_body_rate`); the last row repeats
    the one before it."""
    q = as_quaternions("q_nb", q_nb)
    omega = quat_to_rotvec(quat_multiply(quat_conjugate(q[:-1]), q[1:])) / as_positive("dt", dt)
    return np.vstack([omega, omega[-1:]])


def _dcm_homogeneous(q):
    """``R(q)`` written as a homogeneous quadratic in ``q`` (equal to :func:`quat_to_dcm` for unit q)."""
    w, x, y, z = q
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def body_vector(q, v_n) -> np.ndarray:
    """``R(q)ᵀ v_n``, ``(3,)``: an earth-frame vector seen in the body frame of one quaternion ``q``,
    written as a homogeneous quadratic in ``q`` (its length scales with ``|q|²``; for a unit ``q``
    it is the rotated vector). The measurement model of a gravity or field sensor."""
    return _dcm_homogeneous(_nonzero("q", as_vector("q", q, 4))).T @ as_vector("v_n", v_n, 3)


def vector_jacobian(q, v_n) -> np.ndarray:
    """``∂(R(q)ᵀ v_n)/∂q``, ``(3, 4)``, of :func:`body_vector`: the blocks of Kesten eq. (2.54).

    ``R(q)ᵀ v`` is a homogeneous quadratic in ``q``, so a central difference with unit steps is
    exact: column ``j`` is ``(f(q + e_j) − f(q − e_j)) / 2``.
    """
    q, v = _nonzero("q", as_vector("q", q, 4)), as_vector("v_n", v_n, 3)
    return np.column_stack([_dcm_homogeneous(q + e).T @ v - _dcm_homogeneous(q - e).T @ v for e in np.eye(4)]) / 2.0
