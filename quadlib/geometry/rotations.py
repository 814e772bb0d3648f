"""Euler angles, rotation matrices, and attitude from accelerometer and magnetometer.

Conventions (chapter 0): NED earth frame, FRD body frame, Z-Y-X Euler angles (yaw ψ, pitch θ,
roll φ); ``R_nb`` (Tellex's ``R_bg``) rotates body vectors into NED. The accelerometer measures
specific force ``f_b = R_nbᵀ (a_n − g_n)`` with ``g_n = [0, 0, +g₀]``: level and at rest it
reads ``[0, 0, −g₀]``. Functions accept arrays of angles and broadcast over them.
"""

from __future__ import annotations

import numpy as np

from quadlib.validation import as_angle, as_finite_array, as_float_array

__all__ = ["FREE_FALL_M_S2", "accel_tilt", "dcm_dyaw", "dcm_to_euler", "euler_rate_matrix", "euler_to_dcm",
           "mag_heading", "wrap_angle"]


def _angles(*named):
    return [as_finite_array(name, value) for name, value in named]


def wrap_angle(a) -> np.ndarray:
    """Wrap angles [rad] to (−π, π]; NaN (a missing angle) stays NaN."""
    a = as_float_array("a", a)
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def euler_to_dcm(roll, pitch, yaw) -> np.ndarray:
    """``R_nb`` of Z-Y-X Euler angles [rad], ``(..., 3, 3)``.

    .. math::

        R_{nb} = R_z(\\psi) R_y(\\theta) R_x(\\phi)

    Source: Tellex et al. §7.2, eq. (48) (their ``R_bg``).
    """
    roll, pitch, yaw = _angles(("roll", roll), ("pitch", pitch), ("yaw", yaw))
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    R = np.empty(np.broadcast_shapes(roll.shape, pitch.shape, yaw.shape) + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy
    R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy
    R[..., 2, 0], R[..., 2, 1], R[..., 2, 2] = -sp, cp * sr, cp * cr
    return R


def dcm_dyaw(roll, pitch, yaw) -> np.ndarray:
    """``∂R_nb/∂ψ``, ``(..., 3, 3)``: the yaw derivative the 3D EKF's Jacobian needs.

    Source: Tellex et al. §7.2, eq. (52).
    """
    R = euler_to_dcm(roll, pitch, yaw)
    # R = R_z(ψ) R', and dR_z/dψ = [e_z]× R_z, so ∂R/∂ψ = [e_z]× R: rows (−R₁, R₀, 0)
    dR = np.zeros_like(R)
    dR[..., 0, :], dR[..., 1, :] = -R[..., 1, :], R[..., 0, :]
    return dR


def dcm_to_euler(R) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Z-Y-X Euler angles ``(roll, pitch, yaw)`` [rad] of rotation matrices ``(..., 3, 3)``."""
    R = as_finite_array("R", R)
    if R.shape[-2:] != (3, 3):
        raise ValueError(f"R: expected shape (..., 3, 3), got {R.shape}")
    pitch = np.arcsin(np.clip(-R[..., 2, 0], -1.0, 1.0))
    return np.arctan2(R[..., 2, 1], R[..., 2, 2]), pitch, np.arctan2(R[..., 1, 0], R[..., 0, 0])


def euler_rate_matrix(roll, pitch) -> np.ndarray:
    """``W`` with ``[φ̇, θ̇, ψ̇] = W [p, q, r]``: body rates to Euler-angle rates, ``(..., 3, 3)``.

    .. math::

        W = \\begin{bmatrix} 1 & \\sin\\phi\\tan\\theta & \\cos\\phi\\tan\\theta \\\\
            0 & \\cos\\phi & -\\sin\\phi \\\\
            0 & \\sin\\phi/\\cos\\theta & \\cos\\phi/\\cos\\theta \\end{bmatrix}

    Near hover (small φ, θ) ``W ≈ I``, which is Tellex eq. (39) and the blog's approximation.
    Singular at θ = ±90° (gimbal lock). Source: the blog, "simplest pipeline".
    """
    roll, pitch = np.broadcast_arrays(*_angles(("roll", roll), ("pitch", pitch)))
    cr, sr, cp, tp = np.cos(roll), np.sin(roll), np.cos(pitch), np.tan(pitch)
    one, zero = np.ones_like(roll), np.zeros_like(roll)
    return np.stack([np.stack([one, sr * tp, cr * tp], axis=-1),
                     np.stack([zero, cr, -sr], axis=-1),
                     np.stack([zero, sr / cp, cr / cp], axis=-1)], axis=-2)


FREE_FALL_M_S2 = 2.0
"""Below this specific force [m/s²] an accelerometer gives no tilt."""


def accel_tilt(f_b) -> tuple[np.ndarray, np.ndarray]:
    """Roll and pitch [rad] from specific force ``f_b`` (``(..., 3)``, FRD, reads −g₀ on z at rest).

    .. math::

        \\phi = \\operatorname{atan2}(-f_y, -f_z), \\qquad
        \\theta = \\operatorname{atan2}\\left(f_x, \\sqrt{f_y^2 + f_z^2}\\right)

    NaN where ``|f_b|`` is below ``FREE_FALL_M_S2`` (2 m/s²: in free fall the accelerometer reads
    noise, whose direction means nothing) or the sample is NaN.
    Exact only when the vehicle does not accelerate (``f_b = −R_nbᵀ g_n``). A quadrotor's thrust
    is along body z, so in accelerated flight its accelerometer reads almost no tilt at all.
    Differs from the source: the blog's roll ``atan(A_y / √(A_x² + A_z²))`` is ``asin(A_y/|A|)``,
    which is the roll only at zero pitch, and has the opposite sign with this accelerometer sign.
    """
    f_b = as_float_array("f_b", f_b)
    if f_b.ndim == 0 or f_b.shape[-1] != 3:
        raise ValueError(f"f_b: expected shape (..., 3), got {f_b.shape}")
    fx, fy, fz = np.moveaxis(f_b, -1, 0)
    with np.errstate(invalid="ignore"):
        no_tilt = ~(np.sqrt(fx**2 + fy**2 + fz**2) >= FREE_FALL_M_S2)  # free fall, or a missing sample
    roll, pitch = np.arctan2(-fy, -fz), np.arctan2(fx, np.hypot(fy, fz))
    return np.where(no_tilt, np.nan, roll), np.where(no_tilt, np.nan, pitch)


def mag_heading(m_b, roll, pitch, declination_rad: float = 0.0) -> np.ndarray:
    """Yaw [rad] from a body-frame magnetometer vector and known roll and pitch (tilt compensation).

    The field is rotated into the level (yaw) frame, ``m_l = R_y(θ) R_x(φ) m_b``, and
    ``ψ = atan2(−m_l,y, m_l,x) + declination``, wrapped to (−π, π]. Heading from magnetic north
    when ``declination_rad`` is 0 (Tellex §7). Differs from the source: the blog's
    ``atan(H_x / H_y)`` is neither tilt-compensated nor measured from north.
    """
    m_b = as_finite_array("m_b", m_b)
    if m_b.ndim == 0 or m_b.shape[-1] != 3:
        raise ValueError(f"m_b: expected shape (..., 3), got {m_b.shape}")
    roll, pitch = _angles(("roll", roll), ("pitch", pitch))
    mx, my, mz = np.moveaxis(m_b, -1, 0)
    cr, sr, cp, sp = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch)
    level_x = cp * mx + sp * (sr * my + cr * mz)
    level_y = cr * my - sr * mz
    return wrap_angle(np.arctan2(-level_y, level_x) + as_angle("declination_rad", declination_rad))
