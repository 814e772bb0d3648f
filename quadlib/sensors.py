"""The measurement models that every attitude filter and the inertial navigation filter share: the
accelerometer as gravity, the magnetometer as a heading, the gyro at rest as its own bias.

Each returns a :class:`~quadlib.model.Sensor` over a state whose first four entries are the attitude
quaternion ``q_nb`` (scalar first, body FRD → NED), with its maths in :mod:`quadlib.kernels.attitude`.
:mod:`quadlib.attitude` (the orientation MEKF, chapter 13's filters), :mod:`quadlib.nav` (the INS)
and :mod:`quadlib.control` (the closed loops' estimators) build their filters from them.
"""

from __future__ import annotations

import numpy as np

from quadlib.constants import GRAVITY_N
from quadlib.engine.kernel import Kernel, linear_kernels
from quadlib.kernels import attitude as attitude_maths
from quadlib.model import Sensor
from quadlib.validation import as_bool, as_count, as_positive

__all__ = ["GYRO_NAMES", "gravity_sensor", "heading_sensor", "zero_rate_sensor"]

GYRO_NAMES = ("p [rad/s]", "q [rad/s]", "r [rad/s]")
"""The gyro's three axes (body FRD), as inputs and as the zero-rate sensor's measurements."""


def gravity_sensor(sigma_m_s2: float, gated: bool = True) -> Sensor:
    """The accelerometer as a measurement of attitude: ``R(q)ᵀ (−g_n)`` [m/s²]; ``gated=False`` for
    the low-passed accelerometer, which no χ² gate should test (:class:`~quadlib.model.Sensor`)."""
    as_positive("sigma_m_s2", sigma_m_s2)
    gated = as_bool("gated", gated)
    up = -GRAVITY_N
    return Sensor(name="gravity", measurement_names=("fx", "fy", "fz"), h=Kernel("h", attitude_maths.body_vector, up),
                  H=Kernel("H", attitude_maths.body_vector_H, [*up, 7]), R=sigma_m_s2**2 * np.eye(3), gated=gated)


def heading_sensor(sigma_rad: float, corrects_bias: bool = False, *, dim_x: int = 7,
                   gyro_bias_errors: tuple[int, ...] = (3, 4, 5), tilt_aware: bool = False) -> Sensor:
    """The magnetometer's heading: the sample (its context) turned into the earth frame with the
    attitude, its horizontal angle east of north [rad]. The measurement is the local declination
    (where the field should point). By default it corrects the heading only, never the gyro bias
    (error states ``gyro_bias_errors`` are ``uncorrected``): a field that drifts as the sensor
    moves would otherwise be learnt as a bias and turn the heading long after (VQF keeps the
    magnetometer out of its bias estimate for the same reason). ``corrects_bias`` gives the
    ordinary update, whose optimal gain the RTS smoother assumes.

    The heading's Jacobian is restricted to turns about the vertical
    (:func:`~quadlib.kernels.attitude.heading_only_H`): in error coordinates ``∂ψ/∂δθ = R(q)[2, :]``
    (a body turn ``δθ`` turns the earth frame by ``R δθ``, whose down component is the heading
    change), ``0`` for every other state, written with respect to ``x`` (the quaternion in ``x[:4]``)
    through ``2 Ξ(q)ᵀ``, the inverse of ``∂q/∂δθ = ½ Ξ(q)``. The innovation can then turn the
    attitude about the vertical only: a heading computed with a slightly wrong tilt cannot tilt the
    estimate.

    ``tilt_aware``: the heading a magnetometer gives also moves with the tilt error, by about
    tan(dip) times it. The default update leaves that out (its Jacobian sees the heading only) and,
    where the tilt is uncertain against the heading's noise, then trusts the heading too much.
    With ``tilt_aware`` the full Jacobian (:func:`~quadlib.kernels.attitude.tilt_aware_heading_H`:
    ``m_n = R(q) m_b`` and ``R(q ⊗ exp δθ) ≈ R (I + [δθ]×)`` give ``∂m_n/∂δθ = −R [m_b]×``, and
    ``∂ψ/∂m_n = [−m_n,y, m_n,x, 0] / (m_n,x² + m_n,y²)``) puts the tilt's share
    into the innovation's variance, and the gain corrects one error only, the turn about body z
    (error state 2; the others are ``uncorrected``): the magnetometer still never tilts the
    estimate, and never touches anything else in it. A consider update, so not for the smoother
    (``corrects_bias`` must stay False).

    The state holds the attitude quaternion in ``x[:4]``; ``dim_x`` is its length (7 for
    ``[q, b]``; the inertial navigation filter's 16).
    """
    as_positive("sigma_rad", sigma_rad)
    corrects_bias, tilt_aware = as_bool("corrects_bias", corrects_bias), as_bool("tilt_aware", tilt_aware)
    dim_x = as_count("dim_x", dim_x, low=4)  # the quaternion comes first
    if not (isinstance(gyro_bias_errors, tuple) and all(
            isinstance(i, int) and not isinstance(i, bool) and 0 <= i < dim_x - 1 for i in gyro_bias_errors)):
        raise ValueError(f"gyro_bias_errors: expected a tuple of error-state indices in [0, {dim_x - 2}], "
                         f"got {gyro_bias_errors!r}")
    if tilt_aware and corrects_bias:
        raise ValueError("corrects_bias: expected False with tilt_aware=True (its update corrects the heading only), "
                         "got True")
    if tilt_aware:
        H, uncorrected = attitude_maths.tilt_aware_heading_H, tuple(i for i in range(dim_x - 1) if i != 2)
    else:
        H, uncorrected = attitude_maths.heading_only_H, () if corrects_bias else gyro_bias_errors
    return Sensor(name="heading", measurement_names=("heading [rad]",), context_names=("mx", "my", "mz"),
                  h=Kernel("h", attitude_maths.field_heading, context=True), H=Kernel("H", H, [dim_x], context=True),
                  R=np.full((1, 1), sigma_rad**2), residual=Kernel("residual", attitude_maths.wrapped_difference),
                  uncorrected=uncorrected)


def zero_rate_sensor(sigma_rad_s: float) -> Sensor:
    """The gyro at rest as a measurement of its own bias: ``h(x) = b`` [rad/s], σ per sample."""
    as_positive("sigma_rad_s", sigma_rad_s)
    h, H = linear_kernels(np.eye(3, 7, 4))  # h(x) = x[4:7]
    return Sensor(name="zero rate", measurement_names=GYRO_NAMES, h=h, H=H, R=sigma_rad_s**2 * np.eye(3))
