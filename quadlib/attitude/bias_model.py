"""The attitude-and-gyro-bias model every multiplicative attitude estimator shares, and its
additive 7-state form (Salmony's EKF).

State ``x = [q_nb (4), b (3)]``: the attitude (scalar first) and the gyro's bias [rad/s]; input the
gyro ``ω`` [rad/s]; error ``δx = [δθ (3), δb (3)]`` with ``q ⊗ exp(δθ)`` (a small rotation in the
body frame) and ``b + δb``. Used by the fixed-wing multiplicative EKF and error-state UKF.
"""

from __future__ import annotations

import math

import numpy as np

from quadlib.geometry import kernels
from quadlib.imu import gyro_saturation_noise
from quadlib.model import Model
from quadlib.validation import as_positive, as_vector

__all__ = ["GYRO_NAMES", "STATE_NAMES", "additive_attitude_bias_model", "as_attitude_state", "attitude_bias_model",
           "gyro_error_jacobians", "gyro_step", "gyro_step_jacobian", "normalize_attitude",
           "normalize_attitude_jacobian", "quaternion_rate_matrix"]

STATE_NAMES = ("q0", "q1", "q2", "q3", "b_p [rad/s]", "b_q [rad/s]", "b_r [rad/s]")
GYRO_NAMES = ("p [rad/s]", "q [rad/s]", "r [rad/s]")


def as_attitude_state(name: str, x) -> np.ndarray:
    """``x = [q, b]`` as a finite ``(7,)`` array with a non-zero quaternion, or a named error."""
    x = as_vector(name, x, 7)
    if not x[:4].any():
        raise ValueError(f"{name}: expected a non-zero quaternion in x[:4], got {x[:4].tolist()}")
    return x


def quaternion_rate_matrix(q) -> np.ndarray:
    """``Ξ(q)``, ``(4, 3)``: ``q̇ = ½ Ξ(q) ω`` for body rates ω (``q ⊗ [0, ω] = Ξ(q) ω``)."""
    q0, q1, q2, q3 = as_vector("q", q, 4)
    return np.array([[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]])


def gyro_step(x, u, dt):
    """The exact gyro step of ``x = [q, b]``: ``[q ⊗ exp((ω − b) Δt), b]``, ``(7,)``."""
    return _step(as_attitude_state("x", x), as_vector("u", u, 3), as_positive("dt", dt))


def gyro_step_jacobian(x, u, dt):
    """``∂ gyro_step / ∂x``, ``(7, 7)``, exact. With ``φ = (ω − b) Δt``, ``θ = |φ|``, ``n = φ/θ`` and
    ``δq = exp(φ) = [cos(θ/2), sin(θ/2) n]``: ``∂/∂q`` is right multiplication by ``δq`` and
    ``∂/∂b = −Δt Ξ(q) ∂(sin(θ/2) n)/∂φ − Δt q ∂cos(θ/2)/∂φ``, where ``q ⊗ δq = δq₀ q + Ξ(q) δq_v``."""
    return _step_jacobian(as_attitude_state("x", x), as_vector("u", u, 3), as_positive("dt", dt))


def normalize_attitude(x):
    """The quaternion part back to unit norm, the biases unchanged."""
    return _normalized(as_attitude_state("x", x))


def normalize_attitude_jacobian(x):
    """``∂(normalised x)/∂x``: ``(I − q̂ q̂ᵀ)/|q|`` on the quaternion, the identity on the biases."""
    return _normalized_jacobian(as_attitude_state("x", x))


# The unchecked versions: a filter calls these once per sample, after checking its whole log.

def _step(x, u, dt):
    return np.concatenate([kernels.multiply(x[:4], kernels.exp_rotvec((u - x[4:]) * dt)), x[4:]])


def _step_jacobian(x, u, dt):
    q = x[:4]
    phi = (u - x[4:]) * dt
    theta = math.sqrt(float(phi @ phi))
    c, half = math.cos(theta / 2.0), 0.5 * theta
    sinc = math.sin(half) / theta if theta > 1e-6 else 0.5 - theta**2 / 48.0  # sin(θ/2)/θ
    # d(sin(θ/2)/θ)/dθ / θ, the coefficient of φ φᵀ in ∂(sin(θ/2) n)/∂φ, and its series
    k = (0.5 * c - sinc) / theta**2 if theta > 1e-3 else -1.0 / 24.0 + theta**2 / 960.0
    w, (v0, v1, v2) = c, (sinc * phi).tolist()
    J = np.eye(7)
    J[:4, :4] = [[w, -v0, -v1, -v2], [v0, w, v2, -v1], [v1, -v2, w, v0], [v2, v1, -v0, w]]
    d_w = -0.5 * sinc * phi  # ∂cos(θ/2)/∂φ
    d_v = sinc * np.eye(3) + k * np.outer(phi, phi)  # ∂(sin(θ/2)/θ · φ)/∂φ
    J[:4, 4:] = -dt * (np.outer(q, d_w) + kernels.rate_matrix(q) @ d_v)
    return J


def _normalized(x):
    return np.concatenate([kernels.normalize(x[:4]), x[4:]])


def _normalized_jacobian(x):
    J = np.eye(7)
    norm = math.sqrt(float(x[:4] @ x[:4]))
    q_hat = x[:4] / norm
    J[:4, :4] = (np.eye(4) - np.outer(q_hat, q_hat)) / norm
    return J


def _add_error(x, e):
    return np.concatenate([kernels.multiply(x[:4], kernels.exp_rotvec(e[:3])), x[4:] + e[3:]])


def _error_between(x1, x0):
    return np.concatenate([kernels.rotvec(kernels.multiply(kernels.conjugate(x0[:4]), x1[:4])), x1[4:] - x0[4:]])


def _add_jacobian(x):
    """``∂(x ⊞ δx)/∂δx`` at 0: ``q ⊗ exp(δθ) ≈ q + ½ Ξ(q) δθ``, and the identity for the bias."""
    J = np.zeros((7, 6))
    J[:4, :3] = 0.5 * kernels.rate_matrix(x[:4])
    J[4:, 3:] = np.eye(3)
    return J


def gyro_error_jacobians(phi, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """How an attitude error ``δθ`` (``q ⊗ exp(δθ)``) and a gyro-bias error ``δb`` move through one gyro
    step ``φ = (ω − b) Δt``: ``∂δθ⁺/∂δθ = R(φ)ᵀ`` (the error turns back with the step) and
    ``∂δθ⁺/∂δb = −Δt J_r(φ)``, SO(3)'s right Jacobian
    ``J_r(φ) = I − (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²``, ``θ = |φ|``. Unchecked (a model's ``G``)."""
    theta, K = float(np.linalg.norm(phi)), kernels.skew(phi)
    if theta > 1e-6:
        a, b = (1.0 - np.cos(theta)) / theta**2, (theta - np.sin(theta)) / theta**3
    else:  # the series of both coefficients
        a, b = 0.5 - theta**2 / 24.0, 1.0 / 6.0 - theta**2 / 120.0
    return kernels.dcm(kernels.exp_rotvec(phi)).T, -dt * (np.eye(3) - a * K + b * K @ K)


def _error_jacobian(x, u, dt):
    """``∂δx_{k+1}/∂δx_k`` for ``[δθ, δb]``: :func:`gyro_error_jacobians`, the bias error constant."""
    G = np.eye(6)
    G[:3, :3], G[:3, 3:] = gyro_error_jacobians((u - x[4:]) * dt, dt)
    return G


def attitude_bias_model(gyro_sigma_rad_s: float, gyro_bias_walk_rad_s_sqrt_s: float,
                        gyro_range_rad_s: float | None = None) -> Model:
    """Attitude ``q_nb`` and gyro bias ``b`` (7 states) with a 6-D error ``[δθ, δb]`` (``q ⊗ exp(δθ)``,
    ``b + δb``) and the exact gyro step ``q ⊗ exp((ω − b) Δt)``: the multiplicative EKF's model in
    :class:`~quadlib.ModelEKF`, the error-state UKF's in :class:`~quadlib.ModelUKF`. A sensor's ``H``
    with respect to the 7 states serves it unchanged: it is chained with ``∂(x ⊞ δx)/∂δx``.

    .. math:: Q = \\mathrm{diag}\\big((\\sigma_\\omega \\Delta t)^2 I_3,\\; \\sigma_b^2 \\Delta t\\, I_3\\big)

    With ``gyro_range_rad_s``, a saturated gyro sample adds the attitude variance of
    :func:`~quadlib.imu.saturated_step_variance`.
    """
    sg = as_positive("gyro_sigma_rad_s", gyro_sigma_rad_s)
    sb = as_positive("gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s)
    return Model(state_names=STATE_NAMES, input_names=GYRO_NAMES,
                 g=_step,
                 G=_error_jacobian, Q=lambda dt: np.diag([(sg * dt) ** 2] * 3 + [sb**2 * dt] * 3),
                 error_names=("dtheta_x", "dtheta_y", "dtheta_z", "db_p", "db_q", "db_r"),
                 state_add=_add_error, residual_x=_error_between, add_jacobian=_add_jacobian,
                 normalize=_normalized,
                 input_noise=gyro_saturation_noise(gyro_range_rad_s, [1.0] * 3 + [0.0] * 3),
                 name="attitude and gyro bias, error state")


def additive_attitude_bias_model(gyro_sigma_rad_s: float, gyro_bias_walk_rad_s_sqrt_s: float,
                                 gyro_range_rad_s: float | None = None, name: str = "attitude and gyro bias") -> Model:
    """Attitude ``q_nb`` and gyro bias ``b`` as one additive 7-state: the exact gyro step
    :func:`gyro_step` with its Jacobian :func:`gyro_step_jacobian`, the quaternion renormalised after
    every predict and update (:func:`normalize_attitude`, its Jacobian carrying ``P`` along).

    .. math:: Q = \\mathrm{diag}\\big((\\sigma_\\omega \\Delta t / 2)^2 I_4,\\;
              \\sigma_b^2 \\Delta t\\, I_3\\big)

    With ``gyro_range_rad_s``, a saturated gyro sample adds the attitude variance of
    :func:`~quadlib.imu.saturated_step_variance`.
    """
    sg = as_positive("gyro_sigma_rad_s", gyro_sigma_rad_s)
    sb = as_positive("gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s)
    return Model(state_names=STATE_NAMES, input_names=GYRO_NAMES, g=_step, G=_step_jacobian,
                 Q=lambda dt: np.diag([0.25 * (sg * dt) ** 2] * 4 + [sb**2 * dt] * 3),
                 normalize=_normalized, normalize_jacobian=_normalized_jacobian,
                 input_noise=gyro_saturation_noise(gyro_range_rad_s, [0.25] * 4 + [0.0] * 3), name=name)
