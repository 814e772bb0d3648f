"""Kesten's altitude filter (§2.3–2.4): barometer and vertical acceleration, with a gravity state.

State ``x = [s, v, g̃]``: altitude [m] and vertical speed [m/s], both *up*, and the filter's own
estimate of the vertical specific force at rest, g̃ [m/s²], which absorbs an accelerometer bias
and a local gravity that differs from g₀. Input ``a_z``: the *up* component of the specific force
in the navigation frame (eq. 2.67), ``a_z = −(R_nb f_b)_z``, about +g₀ at rest.

.. math::

    x_{k+1} = \\begin{bmatrix} 1 & \\Delta t & -\\Delta t^2/2 \\\\ 0 & 1 & -\\Delta t \\\\
                              0 & 0 & 1 - w \\end{bmatrix} x_k
        + \\begin{bmatrix} \\Delta t^2/2 \\\\ \\Delta t \\\\ w \\end{bmatrix} a_z

so the vertical acceleration is ``a_z − g̃`` and g̃ follows ``a_z`` through a first-order low-pass
with weight ``w`` per step (Kesten's τ_X, left without a value in the thesis; Kesten writes τ for the
sample period Δt). The input noise
(σ_a) enters through the same vector (eqs. 2.69–2.70). Source: Kesten (2010), eqs. (2.67)–(2.72),
(4.14)–(4.15).
"""

from __future__ import annotations

import numpy as np

from quadlib.geometry.quaternion import as_unit_quaternions, quat_rotate
from quadlib.imu import SATURATED
from quadlib.model import Model, Sensor
from quadlib.validation import as_finite_array, as_positive, as_probability, as_vectors3

__all__ = ["SEA_LEVEL_HPA", "altitude_from_pressure", "altitude_model", "baro_altitude_sensor",
           "pressure_from_altitude", "vertical_specific_force"]

SEA_LEVEL_HPA = 1013.25


def altitude_model(accel_sigma_m_s2: float, gravity_weight: float, accel_range_m_s2: float | None = None) -> Model:
    """Eq. (2.68) with input noise σ_a (eqs. 2.69–2.70; the thesis's σ²_a = 3.5·10⁻³ m²/s⁴).

    Parameters
    ----------
    accel_sigma_m_s2 : float
        Standard deviation of one accelerometer sample [m/s²].
    gravity_weight : float
        ``w`` in (0, 1): how much of each ``a_z`` sample enters g̃ (a time constant of ``τ/w``).
    accel_range_m_s2 : float, optional
        The accelerometer's full scale [m/s²] (16 g is common). An input at it was clipped: the
        acceleration beyond it is unknown, taken as up to the full scale again, so that step adds
        ``range² · B Bᵀ`` to Q (the gyro's rule, :func:`~quadlib.imu.saturated_step_variance`).
    """
    sa = as_positive("accel_sigma_m_s2", accel_sigma_m_s2)
    w = as_probability("gravity_weight", gravity_weight)

    def F(dt):
        return np.array([[1.0, dt, -0.5 * dt**2], [0.0, 1.0, -dt], [0.0, 0.0, 1.0 - w]])

    def B(x, u, dt):
        return np.array([[0.5 * dt**2], [dt], [w]])

    def g(x, u, dt):
        return F(dt) @ x + B(x, u, dt)[:, 0] * u[0]

    def Q(dt):
        b = B(None, None, dt)
        return sa**2 * (b @ b.T)

    input_noise = None
    if accel_range_m_s2 is not None:
        full_scale = as_positive("accel_range_m_s2", accel_range_m_s2)

        def input_noise(u, dt):
            return None if abs(u[0]) < SATURATED * full_scale else (full_scale / sa) ** 2 * Q(dt)

    return Model(state_names=("s [m]", "v [m/s]", "g~ [m/s2]"), input_names=("a_z up [m/s2]",),
                 g=g, G=lambda x, u, dt: F(dt), Q=Q, B=B, input_noise=input_noise, name="Kesten altitude")


def baro_altitude_sensor(sigma_m: float, rate_hz: float | None = 25.0) -> Sensor:
    """Barometric altitude ``s`` (eq. 2.71), noise σ [m] (the thesis's variance 0.15 m²: σ ≈ 0.39 m)."""
    s = as_positive("sigma_m", sigma_m)
    H = np.array([[1.0, 0.0, 0.0]])
    return Sensor(name="baro", measurement_names=("s [m]",), h=lambda x: x[:1], H=lambda x: H,
                  R=np.full((1, 1), s**2), rate_hz=rate_hz)


def vertical_specific_force(q_nb, f_b) -> np.ndarray:
    """Eq. (2.67): the up component of the specific force, ``−(R(q_nb) f_b)_z`` [m/s²], ``(N,)``."""
    return -quat_rotate(as_unit_quaternions("q_nb", q_nb), as_vectors3("f_b", f_b))[..., 2]


def pressure_from_altitude(altitude_m) -> np.ndarray:
    """Eq. (4.14): standard-atmosphere pressure [hPa] at ``altitude_m`` above sea level."""
    s = as_finite_array("altitude_m", altitude_m)
    return SEA_LEVEL_HPA * (1.0 - 0.0065 * s / 288.15) ** 5.255


def altitude_from_pressure(pressure_hpa) -> np.ndarray:
    """Eq. (4.15): altitude [m] at ``pressure_hpa``. Its rounded constants (44330 m, 0.19) invert
    eq. (4.14) to within a few metres over the first kilometre, not exactly (chapter 14)."""
    p = as_finite_array("pressure_hpa", pressure_hpa)
    if np.any(p <= 0):
        raise ValueError(f"pressure_hpa: expected positive pressures, got a minimum of {p.min()}")
    return 44330.0 * (1.0 - (p / SEA_LEVEL_HPA) ** 0.19)
