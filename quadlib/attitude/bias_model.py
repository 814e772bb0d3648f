"""The attitude-and-gyro-bias model every multiplicative attitude estimator shares, and its
additive 7-state form (Salmony's EKF).

State ``x = [q_nb (4), b (3)]``: the attitude (scalar first) and the gyro's bias [rad/s]; input the
gyro ``ω`` [rad/s]; error ``δx = [δθ (3), δb (3)]`` with ``q ⊗ exp(δθ)`` (a small rotation in the
body frame) and ``b + δb``. Used by the fixed-wing multiplicative EKF and error-state UKF.
"""

from __future__ import annotations

import numpy as np

from quadlib.engine.kernel import Kernel
from quadlib.imu import untrusted_gyro_noise
from quadlib.kernels import attitude as k
from quadlib.kernels.attitude import attitude_bias_jacobian
from quadlib.model import Model
from quadlib.sensors import GYRO_NAMES
from quadlib.validation import as_positive, as_vector

__all__ = ["LAYOUT", "STATE_NAMES", "additive_attitude_bias_model", "as_attitude_state", "attitude_bias_model",
           "gyro_error_jacobians", "gyro_step", "gyro_step_jacobian", "normalize_attitude",
           "normalize_attitude_jacobian", "quaternion_rate_matrix"]

STATE_NAMES = ("q0", "q1", "q2", "q3", "b_p [rad/s]", "b_q [rad/s]", "b_r [rad/s]")
LAYOUT = {"q": slice(0, 4), "gyro_bias": slice(4, 7)}  # the parts of x, for FilterRun.layout


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


# The unchecked versions, which a filter calls once per sample after checking its whole log: the
# kernels of quadlib.kernels.attitude, which the compiled engine calls too.
_step = Kernel("g", k.attitude_bias_step)
_step_jacobian = Kernel("G", k.attitude_step_jacobian)
_error_jacobian = Kernel("G", k.attitude_error_jacobian)
_normalized = Kernel("normalize", k.normalize_quaternion)
_normalized_jacobian = Kernel("normalize_jacobian", k.normalize_quaternion_jacobian)
_add_error = Kernel("state_add", k.attitude_bias_add)
_error_between = Kernel("residual_x", k.attitude_bias_difference)
_add_jacobian = Kernel("add_jacobian", k.attitude_bias_add_jacobian)


def gyro_error_jacobians(phi, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """How an attitude error ``δθ`` (``q ⊗ exp(δθ)``) and a gyro-bias error ``δb`` move through one gyro
    step ``φ = (ω − b) Δt``: ``∂δθ⁺/∂δθ = R(φ)ᵀ`` (the error turns back with the step) and
    ``∂δθ⁺/∂δb = −Δt J_r(φ)``, SO(3)'s right Jacobian
    ``J_r(φ) = I − (1 − cos θ)/θ² [φ]× + (θ − sin θ)/θ³ [φ]×²``, ``θ = |φ|``. Unchecked (a model's ``G``)."""
    G = attitude_bias_jacobian(np.require(phi, np.float64, "CW"), float(dt))
    return G[:3, :3], G[:3, 3:]


def _gyro_noise(sg: float, sb: float, quaternion: bool) -> Kernel:
    """``Q(Δt)``: ``(σ_ω Δt)²`` per rotation axis (``¼`` of it per quaternion component), ``σ_b² Δt`` per bias."""
    return Kernel("Q", k.gyro_noise, [sg, 0.0, 0.25, 4, sb, 3] if quaternion else [sg, 0.0, 1.0, 3, sb, 3])


def attitude_bias_model(gyro_sigma_rad_s: float, gyro_bias_walk_rad_s_sqrt_s: float,
                        gyro_range_rad_s: float | None = None, gap_accel_rad_s2: float | None = None) -> Model:
    """Attitude ``q_nb`` and gyro bias ``b`` (7 states) with a 6-D error ``[δθ, δb]`` (``q ⊗ exp(δθ)``,
    ``b + δb``) and the exact gyro step ``q ⊗ exp((ω − b) Δt)``: the multiplicative EKF's model in
    :class:`~quadlib.ModelEKF`, the error-state UKF's in :class:`~quadlib.ModelUKF`. A sensor's ``H``
    with respect to the 7 states serves it unchanged: it is chained with ``∂(x ⊞ δx)/∂δx``.

    .. math:: Q = \\mathrm{diag}\\big((\\sigma_\\omega \\Delta t)^2 I_3,\\; \\sigma_b^2 \\Delta t\\, I_3\\big)

    With ``gyro_range_rad_s``, a saturated gyro sample adds the attitude variance of
    :func:`~quadlib.imu.saturated_step_variance`. With ``gap_accel_rad_s2`` the input has a fourth
    column, the seconds a held sample stands in for missing ones (:func:`~quadlib.imu.gyro_with_gaps`),
    and a held sample adds attitude variance that grows with it (:func:`~quadlib.imu.untrusted_gyro_noise`).
    """
    sg = as_positive("gyro_sigma_rad_s", gyro_sigma_rad_s)
    sb = as_positive("gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s)
    inputs = GYRO_NAMES if gap_accel_rad_s2 is None else GYRO_NAMES + ("held for [s]",)
    return Model(state_names=STATE_NAMES, input_names=inputs,
                 g=_step,
                 G=_error_jacobian, Q=_gyro_noise(sg, sb, quaternion=False),
                 error_names=("dtheta_x", "dtheta_y", "dtheta_z", "db_p", "db_q", "db_r"),
                 state_add=_add_error, residual_x=_error_between, add_jacobian=_add_jacobian,
                 normalize=_normalized,
                 input_noise=untrusted_gyro_noise(gyro_range_rad_s, [1.0] * 3 + [0.0] * 3, gap_accel_rad_s2),
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
                 Q=_gyro_noise(sg, sb, quaternion=True),
                 normalize=_normalized, normalize_jacobian=_normalized_jacobian,
                 input_noise=untrusted_gyro_noise(gyro_range_rad_s, [0.25] * 4 + [0.0] * 3), name=name)
