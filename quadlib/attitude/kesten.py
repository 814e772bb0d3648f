"""The five attitude filters of Kesten (2010) §2.2.3, behind one interface.

Every filter keeps ``q_nb`` (scalar first), predicts with the gyro (eq. 2.7, exact) and corrects
with the accelerometer and the magnetometer:

=======  ====================================  =========================================  ==================
name     state                                 correction                                 built on
=======  ====================================  =========================================  ==================
TOVKF    orientation vector θ (3)              KF on the attitude from a and m (eq. 2.26)  :class:`ModelEKF`
TQKF     quaternion (4)                        KF on the attitude quaternion (eq. 2.37)    :class:`ModelEKF`
TQF      quaternion + one variance             geodesic average (eqs. 2.44–2.48)           scalar recursion
QKF      quaternion (4)                        EKF on a and m separately (eqs. 2.25, 2.54) :class:`ModelEKF`
QF       quaternion + two variances            two rotations toward a and m (2.55–2.64)    scalar recursion
=======  ====================================  =========================================  ==================

The "truncated" filters (T…) first compute an attitude from one accelerometer and one
magnetometer sample (:func:`quadlib.geometry.vector_attitude.attitude_from_accel_mag`), so they correct only when
both are available; QKF and QF use each sensor on its own.

Differs from the source, each time for a reason given in the errata (chapter 10):

* process noise ``(σ_ω τ)²`` per axis (E15), measurement variances ``σ²`` (E16);
* TQKF and QKF: the measured quaternion's sign is matched to the state's before subtracting,
  and the state is renormalised after every update (the thesis renormalises too);
* TOVKF: the measured orientation vector is taken in the representation nearest the state
  (θ or its 2π complement), so the filter survives rotations through 180°;
* QKF: process noise ``(σ_ω τ/2)² I₄`` instead of eq. (2.51)'s ``G Q Gᵀ = (σ_ω τ/2)² (I − q qᵀ)``
  (the extra variance along ``q`` is removed by renormalisation); measured vectors are scaled to
  the predicted lengths before the update, as the thesis's implementation does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.filters import ModelEKF
from quadlib.geometry.quaternion import (
    integrate_body_rate,
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_to_rotvec,
)
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.model import Model, Sensor
from quadlib.validation import as_finite_array, as_positive

__all__ = ["AttitudeNoise", "FILTERS", "QF", "QKF", "TOVKF", "TQF", "TQKF", "run_attitude_filter",
           "vector_jacobian"]


@dataclass(frozen=True)
class AttitudeNoise:
    """Sensor noise and reference vectors (defaults: the thesis's §4.2–4.4, a 0.5 G field, 67° dip).

    ``accel_n`` is the specific force at rest in NED (``−g``, up); ``mag_n`` the field in NED.
    """

    tau: float = 0.004
    sigma_gyro: float = float(np.sqrt(2e-5))
    sigma_accel: float = float(np.sqrt(3.5e-3))
    sigma_mag: float = float(np.sqrt(2e-6))
    accel_n: tuple = (0.0, 0.0, -9.80665)
    mag_n: tuple = field(default=(0.5 * float(np.cos(np.radians(67.0))), 0.0, 0.5 * float(np.sin(np.radians(67.0)))))
    thesis_process_noise: bool = False

    @property
    def q_gyro(self) -> float:
        """Variance of the attitude error one gyro step adds, per axis [rad²]: ``(σ_ω τ)²``, or
        the thesis's ``τ σ²_ω`` (eqs. 2.52, 2.57; 1/τ = 250 times larger) when
        ``thesis_process_noise`` is set (E15)."""
        if self.thesis_process_noise:
            return self.tau * self.sigma_gyro**2
        return (self.sigma_gyro * self.tau) ** 2

    @property
    def r_accel(self) -> float:
        """Angular variance of one accelerometer direction, σ²_a/|a|² (eq. 2.33)."""
        return self.sigma_accel**2 / float(np.dot(self.accel_n, self.accel_n))

    @property
    def r_mag(self) -> float:
        """Angular variance of one magnetometer direction, σ²_m/|m|² (eq. 2.34)."""
        return self.sigma_mag**2 / float(np.dot(self.mag_n, self.mag_n))


def _dcm_h(q):
    """``R(q)`` written as a homogeneous quadratic in ``q`` (equal to the usual one for unit q)."""
    w, x, y, z = q
    return np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])


def vector_jacobian(q, v_n) -> np.ndarray:
    """``∂(R(q)ᵀ v_n)/∂q``, ``(3, 4)``: the blocks of Kesten eq. (2.54).

    ``R(q)ᵀ v`` is a homogeneous quadratic in ``q``, so a central difference with unit steps is
    exact: column ``j`` is ``(f(q + e_j) − f(q − e_j)) / 2``.
    """
    q, v = np.asarray(q, dtype=float), np.asarray(v_n, dtype=float)
    return np.column_stack([(_dcm_h(q + e).T @ v - _dcm_h(q - e).T @ v) / 2.0 for e in np.eye(4)])


class _AttitudeFilter:
    """Common interface: ``predict(omega_b)``, ``update(f_b, m_b)`` (either may be None), ``q``."""

    name = "?"
    truncated = False

    def __init__(self, noise: AttitudeNoise, q0=(1.0, 0.0, 0.0, 0.0), sigma0_rad: float = 1.0):
        if not isinstance(noise, AttitudeNoise):
            raise TypeError(f"noise: expected an AttitudeNoise, got {type(noise).__name__}")
        self.noise = noise
        self.sigma0 = as_positive("sigma0_rad", sigma0_rad)
        self._init(quat_normalize(as_finite_array("q0", q0)))

    def update(self, f_b=None, m_b=None) -> None:
        """Correct with whichever samples are given (truncated filters need both)."""
        if self.truncated:
            if f_b is not None and m_b is not None:
                att = attitude_from_accel_mag(np.atleast_2d(f_b), np.atleast_2d(m_b))
                if att.valid[0]:
                    self.update_attitude(att.q_nb[0])
            return
        if f_b is not None and np.linalg.norm(f_b) > 2.0:  # not in free fall
            self._update_vector(np.asarray(f_b, dtype=float), "accel")
        if m_b is not None:
            self._update_vector(np.asarray(m_b, dtype=float), "mag")


class _GeodesicFilter(_AttitudeFilter):
    """Shared by TQF and QF: the quaternion is turned, never added to; variances are scalars."""

    def _init(self, q0):
        self._q = q0
        self._p = {"attitude": self.sigma0**2, "accel": self.sigma0**2, "mag": self.sigma0**2}

    @property
    def q(self) -> np.ndarray:
        return self._q

    def predict(self, omega_b) -> None:
        self._q = integrate_body_rate(self._q, omega_b, self.noise.tau)
        for key in self._p:
            self._p[key] += self.noise.q_gyro

    def _turn(self, key, r, theta) -> None:
        k = self._p[key] / (self._p[key] + r)
        self._q = quat_multiply(self._q, quat_from_rotvec(k * theta))
        self._p[key] *= 1.0 - k


class TQF(_GeodesicFilter):
    """Truncated quaternion filter: a scalar-gain step along the geodesic toward the measured
    attitude (eqs. 2.44–2.48)."""

    name, truncated = "TQF", True

    def update_attitude(self, z_q) -> None:
        """Correct with an attitude computed from accelerometer and magnetometer (truncated)."""
        r = 0.5 * (self.noise.r_accel + self.noise.r_mag)
        self._turn("attitude", r, quat_to_rotvec(quat_multiply(quat_conjugate(self._q), z_q)))


class QF(_GeodesicFilter):
    """Quaternion filter: two scalar variances, and rotations that bring the predicted gravity and
    field directions toward the measured ones (eqs. 2.55–2.64)."""

    name = "QF"

    def _update_vector(self, z_b, which) -> None:
        ref = self.noise.accel_n if which == "accel" else self.noise.mag_n
        predicted = _dcm_h(self._q).T @ np.asarray(ref, dtype=float)
        a, b = z_b / np.linalg.norm(z_b), predicted / np.linalg.norm(predicted)
        axis = np.cross(a, b)
        s = np.linalg.norm(axis)
        if s < 1e-12:
            return
        theta = axis / s * np.arccos(np.clip(a @ b, -1.0, 1.0))  # eqs. (2.61), (2.63)
        self._turn(which, self.noise.r_accel if which == "accel" else self.noise.r_mag, theta)


class _KalmanAttitudeFilter(_AttitudeFilter):
    """A filter whose correction is a quadlib ModelEKF update."""

    @property
    def q(self) -> np.ndarray:
        return self._state_to_q(self.kf.estimate)

    def predict(self, omega_b) -> None:
        self.kf.predict(np.asarray(omega_b, dtype=float), self.noise.tau)


def _quat_model(noise: AttitudeNoise, q_scale: float) -> Model:
    return Model(state_names=("w", "x", "y", "z"), input_names=("p", "q", "r"),
                 g=lambda x, u, dt: integrate_body_rate(x, u, dt), G=lambda x, u, dt: np.eye(4),
                 Q=lambda dt: q_scale * noise.q_gyro * np.eye(4), name="gyro-driven quaternion")


class TOVKF(_KalmanAttitudeFilter):
    """Truncated orientation-vector Kalman filter: state θ, H = I₃, Φ = I₃ (eqs. 2.26–2.35)."""

    name, truncated = "TOVKF", True

    def _init(self, q0):
        n = self.noise
        model = Model(state_names=("theta_x", "theta_y", "theta_z"), input_names=("p", "q", "r"),
                      g=lambda x, u, dt: quat_to_rotvec(integrate_body_rate(quat_from_rotvec(x), u, dt)),
                      G=lambda x, u, dt: np.eye(3), Q=lambda dt: n.q_gyro * np.eye(3), name="orientation vector")

        def nearest(z, x):  # z, or the same attitude turned the other way round, whichever is nearer x
            angle = np.linalg.norm(z)
            if angle < 1e-12:
                return z - x
            other = z - 2 * np.pi * z / angle
            return (z if np.linalg.norm(z - x) <= np.linalg.norm(other - x) else other) - x

        self.sensor = Sensor(name="attitude", measurement_names=("tx", "ty", "tz"), h=lambda x: x,
                             H=lambda x: np.eye(3), R=0.5 * (n.r_accel + n.r_mag) * np.eye(3), residual=nearest)
        self.kf = ModelEKF(model, quat_to_rotvec(q0), self.sigma0**2 * np.eye(3), n.tau)

    @staticmethod
    def _state_to_q(x):
        return quat_from_rotvec(x)

    def update_attitude(self, z_q) -> None:
        self.kf.update_sensor(self.sensor, quat_to_rotvec(z_q))


class TQKF(_KalmanAttitudeFilter):
    """Truncated quaternion Kalman filter: state q, H = I₄, Φ = I₄ (eqs. 2.36–2.43)."""

    name, truncated = "TQKF", True

    def _init(self, q0):
        n = self.noise
        self.sensor = Sensor(name="attitude", measurement_names=("w", "x", "y", "z"), h=lambda x: x,
                             H=lambda x: np.eye(4), R=0.25 * 0.5 * (n.r_accel + n.r_mag) * np.eye(4),
                             residual=lambda z, x: (z if z @ x >= 0 else -z) - x)
        self.kf = ModelEKF(_quat_model(n, 0.25), q0, 0.25 * self.sigma0**2 * np.eye(4), n.tau)

    @staticmethod
    def _state_to_q(x):
        return quat_normalize(x)

    def update_attitude(self, z_q) -> None:
        self.kf.update_sensor(self.sensor, z_q)
        self.kf.x = quat_normalize(self.kf.estimate).reshape(-1, 1)


class QKF(_KalmanAttitudeFilter):
    """Quaternion Kalman filter: the accelerometer and the magnetometer as nonlinear measurements
    of q (eqs. 2.25, 2.49–2.54), each updated on its own."""

    name = "QKF"

    def _init(self, q0):
        n = self.noise
        self.sensors = {}
        for which, ref, r in (("accel", n.accel_n, n.sigma_accel**2), ("mag", n.mag_n, n.sigma_mag**2)):
            ref = np.asarray(ref, dtype=float)
            self.sensors[which] = Sensor(name=which, measurement_names=("x", "y", "z"),
                                         h=lambda x, ref=ref: _dcm_h(x).T @ ref,
                                         H=lambda x, ref=ref: vector_jacobian(x, ref), R=r * np.eye(3))
        self.kf = ModelEKF(_quat_model(n, 0.25), q0, 0.25 * self.sigma0**2 * np.eye(4), n.tau)

    @staticmethod
    def _state_to_q(x):
        return quat_normalize(x)

    def _update_vector(self, z_b, which) -> None:
        sensor = self.sensors[which]
        predicted = sensor.h(self.kf.estimate)
        self.kf.update_sensor(sensor, z_b * (np.linalg.norm(predicted) / np.linalg.norm(z_b)))
        self.kf.x = quat_normalize(self.kf.estimate).reshape(-1, 1)


FILTERS = {cls.name: cls for cls in (TOVKF, TQKF, TQF, QKF, QF)}


def run_attitude_filter(filt, gyro, accel, mag) -> np.ndarray:
    """Run ``filt`` over ``N`` samples: ``(N, 4)`` attitude estimates.

    ``gyro[k]`` turns sample ``k`` into ``k + 1``; ``accel`` and ``mag`` hold NaN rows where a
    sensor has no sample (a lower rate, an outage).
    """
    gyro = as_finite_array("gyro", gyro, ndim=2)
    accel, mag = np.asarray(accel, dtype=float), np.asarray(mag, dtype=float)
    if gyro.shape[1] != 3 or accel.shape != gyro.shape or mag.shape != gyro.shape:
        raise ValueError(f"gyro, accel, mag: expected three (N, 3) arrays, got {gyro.shape}, {accel.shape}, "
                         f"{mag.shape}")
    out = np.empty((len(gyro), 4))
    has_a, has_m = ~np.isnan(accel).any(axis=1), ~np.isnan(mag).any(axis=1)
    if filt.truncated:  # the attitude measurements, computed for the whole log at once
        both = has_a & has_m
        measured = attitude_from_accel_mag(accel[both], mag[both])
        attitude = np.full((len(gyro), 4), np.nan)
        attitude[np.flatnonzero(both)[measured.valid]] = measured.q_nb[measured.valid]
    for k in range(len(gyro)):
        if k:
            filt.predict(gyro[k - 1])
        if filt.truncated:
            if not np.isnan(attitude[k, 0]):
                filt.update_attitude(attitude[k])
        else:
            filt.update(accel[k] if has_a[k] else None, mag[k] if has_m[k] else None)
        out[k] = filt.q
    return out
