"""Salmony's fixed-wing attitude model (2019): quaternion + gyro bias, accelerometer with airspeed.

State ``x = [q0, q1, q2, q3, b_p, b_q, b_r]`` (eq. 3): ``q_nb`` scalar first and the gyro biases
[rad/s]; input the gyro rates ``ω = [p, q, r]``. Continuous dynamics (eqs. 9–11, corrected):

.. math::

    \\dot q = \\tfrac12\\,\\Xi(q)\\,(\\omega - b), \\qquad \\dot b = 0, \\qquad
    \\Xi(q) = \\begin{bmatrix} -q_1 & -q_2 & -q_3 \\\\ q_0 & -q_3 & q_2 \\\\ q_3 & q_0 & -q_1 \\\\
        -q_2 & q_1 & q_0 \\end{bmatrix}

Measurements: the accelerometer with the airspeed terms of eq. (13) (level flight along body x at
airspeed ``V_a``, ``a^b = ω × [V_a, 0, 0] − R(q)ᵀ g_n``) and the magnetometer as a unit vector
(eq. 14, with an optional inclination the document leaves out). All functions are pure; the
Jacobians are exact and tested against sympy and finite differences.

The second half of the module turns these functions into quadlib models and sensors: Salmony's
EKF model (:func:`fixedwing_model`), an error-state model for the multiplicative EKF and the
error-state UKF (:func:`quadlib.attitude.attitude_bias_model`, shared with every attitude
estimator), and the two sensors. The accelerometer needs
the gyro rates and the airspeed of its own sample; they come with each sample as the sensor's
*context*, so one sensor object serves the whole flight.

Differs from the source (errata E18–E21, chapter 15 and the appendix): eq. (11) already holds
the ½ that eq. (10) applies again; eq. (12)'s last row has the wrong sign on ``∂q̇₃/∂b_r``;
eq. (14)'s second row has the wrong sign on its ``q₁q₂`` term (the printed C matrix is the
Jacobian of the corrected row).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.attitude.bias_model import additive_attitude_bias_model, as_attitude_state, quaternion_rate_matrix
from quadlib.constants import G0, earth_field_ned
from quadlib.engine.kernel import Kernel
from quadlib.geometry.quaternion import as_unit_quaternions
from quadlib.imu import ImuNoise
from quadlib.kernels import fixedwing as fw
from quadlib.model import Model, Sensor
from quadlib.sensors import GYRO_NAMES
from quadlib.validation import as_angle, as_finite_array, as_finite_number, as_float_array, as_positive, as_vector

__all__ = ["FixedWingNoise", "accel_jacobian", "accel_model", "airspeed_from_pressure", "fixedwing_A",
           "fixedwing_accel_sensor", "fixedwing_f", "fixedwing_mag_sensor", "fixedwing_model",
           "lowpass2", "mag_jacobian", "mag_model"]



def fixedwing_f(x, omega) -> np.ndarray:
    """``ẋ = f(x, ω)`` (eqs. 9–11, corrected): ``(7,)``."""
    x, omega = as_attitude_state("x", x), as_vector("omega", omega, 3)
    return np.concatenate([0.5 * quaternion_rate_matrix(x[:4]) @ (omega - x[4:]),
                           np.zeros(3)])


def fixedwing_A(x, omega) -> np.ndarray:
    """``A = ∂f/∂x`` (eq. 12, corrected), ``(7, 7)``."""
    x = as_attitude_state("x", x)
    p, q, r = as_vector("omega", omega, 3) - x[4:]
    A = np.zeros((7, 7))
    A[:4, :4] = 0.5 * np.array([[0, -p, -q, -r], [p, 0, r, -q], [q, -r, 0, p], [r, q, -p, 0]])
    A[:4, 4:] = -0.5 * quaternion_rate_matrix(x[:4])
    return A


def _accel_args(x, omega, airspeed_m_s, g):
    return (as_attitude_state("x", x), as_vector("omega", omega, 3), as_finite_number("airspeed_m_s", airspeed_m_s),
            as_positive("g", g))


def _unit_attitude(x):
    """``x = [q, b]`` checked, its quaternion within ``UNIT_TOLERANCE`` of unit norm (a model of a
    rotation; the Jacobians accept any non-zero ``q``)."""
    x = as_attitude_state("x", x)
    as_unit_quaternions("x[:4]", x[:4])
    return x


def accel_model(x, omega, airspeed_m_s: float, g: float = G0) -> np.ndarray:
    """Eq. (13): specific force in the body frame, ``(3,)`` [m/s²]."""
    x, omega, airspeed_m_s, g = _accel_args(x, omega, airspeed_m_s, g)
    return _accel(_unit_attitude(x), omega, airspeed_m_s, g)


def accel_jacobian(x, omega, airspeed_m_s: float, g: float = G0) -> np.ndarray:
    """``∂(eq. 13)/∂x``, ``(3, 7)`` (the first three rows of Salmony's C; it does not depend on ``omega``)."""
    return _accel_jacobian(*_accel_args(x, omega, airspeed_m_s, g))


def mag_model(x, declination_rad: float, inclination_rad: float = 0.0) -> np.ndarray:
    """Eq. (14), corrected: the unit field ``R(q)ᵀ m_n`` in the body frame. The document's
    model is ``inclination_rad = 0`` (a horizontal field)."""
    return _mag(_unit_attitude(x), earth_field_ned(1.0, inclination_rad, declination_rad))


def mag_jacobian(x, declination_rad: float, inclination_rad: float = 0.0) -> np.ndarray:
    """``∂(mag_model)/∂x``, ``(3, 7)``, exact."""
    return _mag_jacobian(as_attitude_state("x", x), earth_field_ned(1.0, inclination_rad, declination_rad))


# The unchecked versions, called once per sample by the sensors below: the kernels of
# quadlib.kernels.fixedwing, which the compiled engine calls too.

def _accel_kernel(airspeed: bool, g: float = G0, role: str = "h") -> Kernel:
    return Kernel(role, fw.airspeed_accel if role == "h" else fw.airspeed_accel_H, [g, float(airspeed)],
                  context=True)


def _accel(x, omega, airspeed_m_s, g):
    return _accel_kernel(True, g)(x, np.r_[omega, airspeed_m_s])


def _accel_jacobian(x, omega, airspeed_m_s, g):
    return _accel_kernel(True, g, "H")(x, np.r_[omega, airspeed_m_s])


def _mag(x, field_n):
    return Kernel("h", fw.unit_field, field_n)(x)


def _mag_jacobian(x, field_n):
    return Kernel("H", fw.unit_field_H, field_n)(x)


def lowpass2(x, cutoff_hz: float, dt: float) -> np.ndarray:
    """Eq. (8): the critically damped second-order low-pass (eq. 7) by backward Euler, ``(N, ...)``.

    Starts from rest at the first present sample (``y₋₁ = y₋₂ = x₀``), so a constant input passes
    unchanged. A missing sample (a row with NaN) gives a NaN output and leaves the filter's state
    as it was: a gap neither feeds zeros into the filter nor restarts it.
    """
    x = as_float_array("x", x)
    wt = 2 * as_positive("cutoff_hz", cutoff_hz) * np.pi * as_positive("dt", dt)
    den = 1 + 2 * wt + wt**2
    y = np.full_like(x, np.nan)
    present = ~np.isnan(x.reshape(len(x), -1)).any(axis=1)
    if not present.any():
        return y
    y1 = y2 = x[np.argmax(present)]
    for n in np.flatnonzero(present):
        y[n] = (wt**2 * x[n] + 2 * (1 + wt) * y1 - y2) / den
        y2, y1 = y1, y[n]
    return y


def airspeed_from_pressure(dp_pa, rho_kg_m3: float = 1.225) -> np.ndarray:
    """Eq. (2): pitot airspeed ``√(2 ΔP / ρ)`` [m/s]."""
    dp = as_finite_array("dp_pa", dp_pa)
    if np.any(dp < 0):
        raise ValueError(f"dp_pa: expected non-negative differential pressures, got a minimum of {dp.min()}")
    return np.sqrt(2.0 * dp / as_positive("rho_kg_m3", rho_kg_m3))


# --- quadlib models and sensors ------------------------------------------------------------

@dataclass(frozen=True)
class FixedWingNoise(ImuNoise):
    """The fixed-wing flight's sensor errors per sample (at the flight's rate) and the Earth's field.

    Besides :class:`~quadlib.imu.ImuNoise`'s fields (here ``mag_sigma`` is on the unit field vector):
    ``airspeed_sigma_m_s`` [m/s], ``declination_rad`` and ``inclination_rad`` of the field [rad].
    """

    gyro_sigma_rad_s: float = 0.005
    gyro_bias_rad_s: tuple = (0.02, -0.015, 0.01)
    gyro_bias_walk_rad_s_sqrt_s: float = 1e-4
    accel_sigma_m_s2: float = 0.15
    mag_sigma: float = 0.01
    airspeed_sigma_m_s: float = 0.3
    declination_rad: float = field(default=float(np.radians(3.0)))
    inclination_rad: float = field(default=float(np.radians(65.0)))

    FIELDS = ImuNoise.FIELDS | {"airspeed_sigma_m_s": "nonnegative", "declination_rad": "finite",
                                "inclination_rad": "finite"}


def fixedwing_model(gyro_sigma_rad_s: float, gyro_bias_walk_rad_s_sqrt_s: float,
                    gyro_range_rad_s: float | None = None) -> Model:
    """Salmony's EKF model: eqs. (9)–(12), corrected (E18, E19), on the full 7-state; process noise
    from the gyro's white noise and the bias random walk.

    The step integrates eq. (9) exactly over ``Δt`` at a constant rate,
    ``q ⊗ exp((ω − b) Δt)`` (:func:`~quadlib.attitude.gyro_step`), with its exact Jacobian ``G``.
    The document's Euler step ``x + Δt f(x, ω)``, ``G = I + Δt A``, agrees to first order in
    ``|ω| Δt`` but falls behind in fast turns: at 42 rad/s and 50 Hz it loses 18° per roll
    (``tests/fixedwing/test_estimate.py``).

    .. math:: Q = \\mathrm{diag}\\big((\\sigma_\\omega \\Delta t / 2)^2 I_4,\\;
              \\sigma_b^2 \\Delta t\\, I_3\\big)

    The quaternion is renormalised after every predict and update (§8.2). With
    ``gyro_range_rad_s``, a saturated gyro sample adds the attitude variance of
    :func:`~quadlib.imu.saturated_step_variance`.
    """
    return additive_attitude_bias_model(gyro_sigma_rad_s, gyro_bias_walk_rad_s_sqrt_s, gyro_range_rad_s,
                                        name="Salmony fixed-wing")


def fixedwing_accel_sensor(sigma_m_s2: float, unmodelled_m_s2: float | None = None) -> Sensor:
    """Eq. (13) as a sensor whose context is this sample's gyro rates and airspeed, ``[p, q, r, V_a]``.

    With ``unmodelled_m_s2`` it is the model for a failed pitot (§8.3): no airspeed terms, context
    ``[p, q, r]``, and ``R`` inflated by the centripetal acceleration it can no longer predict.
    """
    s = as_positive("sigma_m_s2", sigma_m_s2)
    names = ("ax [m/s2]", "ay [m/s2]", "az [m/s2]")
    if unmodelled_m_s2 is None:
        return Sensor(name="accel", measurement_names=names, context_names=GYRO_NAMES + ("V_a [m/s]",),
                      h=_accel_kernel(True), H=_accel_kernel(True, role="H"), R=s**2 * np.eye(3))
    var = s**2 + as_positive("unmodelled_m_s2", unmodelled_m_s2) ** 2
    return Sensor(name="accel (no airspeed)", measurement_names=names, context_names=GYRO_NAMES,
                  h=_accel_kernel(False), H=_accel_kernel(False, role="H"), R=var * np.eye(3))


def fixedwing_mag_sensor(declination_rad: float, sigma: float, inclination_rad: float = 0.0) -> Sensor:
    """Eq. (14), corrected (E20), on the unit field; ``inclination_rad = 0`` is the document's
    horizontal field. ``sigma`` is per axis of the unit vector."""
    s = as_positive("sigma", sigma)
    field_n = earth_field_ned(1.0, as_finite_number("inclination_rad", inclination_rad),
                              as_angle("declination_rad", declination_rad))
    return Sensor(name="mag", measurement_names=("mx", "my", "mz"), h=Kernel("h", fw.unit_field, field_n),
                  H=Kernel("H", fw.unit_field_H, field_n), R=s**2 * np.eye(3))
