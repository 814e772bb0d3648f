"""The 3D quadrotor of Tellex et al. §7: position, velocity and yaw, driven by the IMU.

State ``x = [x, y, z, ẋ, ẏ, ż, ψ]`` (eq. 36; NED position [m], velocity [m/s], yaw [rad]).
Input ``u = [f_x, f_y, f_z, ψ̇, φ, θ]``: the accelerometer's specific force in the body frame
[m/s²] and the yaw rate [rad/s] (eq. 37), plus the roll and pitch [rad] that an attitude filter
supplies (the source uses them inside ``R_bg`` without listing them as inputs).

.. math::

    g(x, u, \\Delta t) = \\begin{bmatrix} p + v\\,\\Delta t \\\\
        v + (R_{nb}(\\phi, \\theta, \\psi)\\, f + g_n)\\,\\Delta t \\\\
        \\psi + \\dot\\psi\\,\\Delta t \\end{bmatrix}, \\qquad g_n = [0, 0, +g_0]

Source: Tellex et al. §7.2–7.3, eqs. (36)–(58). Differs from the source (erratum E10): eq. (49)
subtracts ``g Δt`` from ``ż``. In NED (§7.4) z points down and an accelerometer at rest reads
``f = −R_nbᵀ g_n``; the velocity must *gain* ``g Δt`` so that a hovering drone stays put.
``gravity="seed"`` gives the printed sign for comparison. The yaw is wrapped to (−π, π] after
every step, and the magnetometer's innovation is wrapped too.
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import G0
from quadlib.engine import Kernel
from quadlib.engine.kernel import linear_kernels
from quadlib.kernels import attitude as att
from quadlib.kernels import quad3d as k
from quadlib.model import Model, Sensor
from quadlib.validation import as_count, as_finite_array, as_positive, as_vector

__all__ = ["imu_inputs", "quad3d_baro_sensor", "quad3d_gps_sensor", "quad3d_mag_sensor",
           "quad3d_model", "quad3d_ukf_options"]

YAW = 6


def quad3d_model(accel_sigma_m_s2, yaw_rate_sigma_rad_s: float, gravity: str = "ned") -> Model:
    """Tellex §7.2 transition (eq. 49) and Jacobian (eqs. 50–52), with white process noise: the
    kernels of :mod:`quadlib.kernels.quad3d`, which the readable filters and the compiled engine call.

    Parameters
    ----------
    accel_sigma_m_s2 : float or (3,) array_like
        Standard deviation of the acceleration error per step [m/s²] (accelerometer noise of the
        input sample), per NED axis; it enters ``v`` as ``σ Δt`` and ``p`` as ``σ Δt²/2``.
    yaw_rate_sigma_rad_s : float
        Standard deviation of the yaw-rate input error [rad/s].
    gravity : {"ned", "seed"}
        ``"ned"``: ``+g₀ Δt`` on ``ż`` (default); ``"seed"``: ``−g₀ Δt`` as printed in eq. (49).
    """
    sa = as_finite_array("accel_sigma_m_s2", accel_sigma_m_s2)
    if sa.shape not in ((), (1,), (3,)):
        raise ValueError(f"accel_sigma_m_s2: expected one σ or three (x, y, z), got shape {sa.shape}")
    sa = np.broadcast_to(sa, (3,)).astype(float)
    if np.any(sa <= 0):
        raise ValueError(f"accel_sigma_m_s2: expected positive values, got {sa.tolist()}")
    sr = as_positive("yaw_rate_sigma_rad_s", yaw_rate_sigma_rad_s)
    if gravity not in ("ned", "seed"):
        raise ValueError(f"gravity: expected 'ned' or 'seed', got {gravity!r}")
    g_down = G0 if gravity == "ned" else -G0
    return Model(state_names=("x [m]", "y [m]", "z [m]", "vx [m/s]", "vy [m/s]", "vz [m/s]", "yaw [rad]"),
                 input_names=("fx [m/s2]", "fy [m/s2]", "fz [m/s2]", "yaw rate [rad/s]", "roll [rad]",
                              "pitch [rad]"),
                 g=Kernel("g", k.quad3d_step, [g_down]), G=Kernel("G", k.quad3d_jacobian),
                 Q=Kernel("Q", k.quad3d_noise, [*sa, sr]), name=f"quad3d ({gravity})")


def quad3d_gps_sensor(pos_sigma_m=(0.7, 0.7, 2.0), vel_sigma_m_s=(0.1, 0.1, 0.3), rate_hz: float | None = 10.0,
                      reset_after_s: float | None = 1.0) -> Sensor:
    """GPS position and velocity (eqs. 53–55): ``h(x) = x[:6]``, ``H = [I₆ 0]``.

    Position and velocity are gated separately (a jump in position says nothing against the
    velocity). A group rejected for ``reset_after_s`` [s] is reset and used again: autopilots do
    the same — PX4's EKF2 resets to GNSS after a rejection timeout, ArduPilot's EKF3 after a retry
    time of several seconds; 1 s (ten fixes) is short enough to rejoin a receiver within 2 s of a
    persistent jump or the end of an outage, and long enough that single glitches stay gated.
    ``None`` keeps the plain gate, which can lock GPS out for good (chapter 11 shows it).
    """
    sigma = np.concatenate([as_vector("pos_sigma_m", pos_sigma_m, 3), as_vector("vel_sigma_m_s", vel_sigma_m_s, 3)])
    if np.any(sigma <= 0):
        raise ValueError(f"pos_sigma_m, vel_sigma_m_s: expected positive values, got {sigma.tolist()}")
    h, H = linear_kernels(np.eye(6, 7))  # h(x) = [p, v]
    return Sensor(name="gps", measurement_names=("x [m]", "y [m]", "z [m]", "vx [m/s]", "vy [m/s]", "vz [m/s]"),
                  h=h, H=H, R=np.diag(sigma**2), rate_hz=rate_hz,
                  groups=((0, 1, 2), (3, 4, 5)), reset_after_s=reset_after_s)


def quad3d_mag_sensor(sigma_rad: float = 0.1, rate_hz: float | None = 100.0) -> Sensor:
    """Magnetometer heading (eqs. 56–58): ``h(x) = ψ``; innovations wrapped to (−π, π]."""
    h, H = linear_kernels(np.eye(1, 7, YAW))  # h(x) = ψ
    return Sensor(name="mag", measurement_names=("yaw [rad]",), h=h, H=H,
                  R=np.full((1, 1), as_positive("sigma_rad", sigma_rad) ** 2),
                  residual=Kernel("residual", att.wrapped_difference), mean=Kernel("mean", att.circular_mean, [0]),
                  rate_hz=rate_hz)


def quad3d_baro_sensor(sigma_m: float = 0.5, rate_hz: float | None = 25.0) -> Sensor:
    """Barometric altitude ``−z`` [m]."""
    H = np.zeros((1, 7))
    H[0, 2] = -1.0
    return Sensor(name="baro", measurement_names=("altitude [m]",), h=lambda x: -x[2:3], H=lambda x: H,
                  R=np.full((1, 1), as_positive("sigma_m", sigma_m) ** 2), rate_hz=rate_hz)


def quad3d_ukf_options() -> dict:
    """``residual_x`` and ``x_mean_fn`` for :class:`quadlib.ModelUKF`: the yaw is averaged on the
    circle and its differences are wrapped."""

    return {"residual_x": Kernel("residual_x", att.angle_difference, [YAW]),
            "x_mean_fn": Kernel("mean", att.circular_mean, [YAW])}


def imu_inputs(dt_imu: float, accel, gyro, roll_pitch, decimate: int = 1) -> np.ndarray:
    """Model inputs ``(M, 6)`` from IMU samples and attitude-filter roll and pitch.

    Blocks of ``decimate`` consecutive samples are averaged (the filter then predicts at
    ``1 / (decimate · dt_imu)``); the yaw rate is the third row of the body-to-Euler-rate matrix,
    ``ψ̇ = (sin φ q + cos φ r) / cos θ``.

    Parameters
    ----------
    dt_imu : float
        IMU sample period [s].
    accel, gyro : (N, 3) specific force [m/s²] and body rates [rad/s]
    roll_pitch : (N, 2) roll and pitch [rad] from an attitude filter
    decimate : int
        Samples per filter step; ``N`` is truncated to a multiple of it.
    """
    as_positive("dt_imu", dt_imu)
    accel, gyro = as_finite_array("accel", accel, ndim=2), as_finite_array("gyro", gyro, ndim=2)
    roll_pitch = as_finite_array("roll_pitch", roll_pitch, ndim=2)
    n = accel.shape[0]
    if accel.shape != (n, 3) or gyro.shape != (n, 3) or roll_pitch.shape != (n, 2):
        raise ValueError(f"accel, gyro, roll_pitch: expected shapes (N, 3), (N, 3), (N, 2), got "
                         f"{accel.shape}, {gyro.shape}, {roll_pitch.shape}")
    decimate = as_count("decimate", decimate, high=n)
    roll, pitch = roll_pitch[:, 0], roll_pitch[:, 1]
    yaw_rate = (np.sin(roll) * gyro[:, 1] + np.cos(roll) * gyro[:, 2]) / np.cos(pitch)
    u = np.column_stack([accel, yaw_rate, roll, pitch])
    m = n // decimate
    return u[: m * decimate].reshape(m, decimate, 6).mean(axis=1)
