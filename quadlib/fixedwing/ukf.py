"""An error-state (multiplicative) UKF for the fixed-wing attitude problem, on filterpy's UKF.

The UKF's state is ``e = [δθ, b]``: a small rotation (3) of the body away from a reference
attitude ``q_ref`` that is kept *outside* the filter, and the gyro bias (3). Sigma points are
spread in this six-dimensional Euclidean space, so filterpy's plain mean, residual and addition
are the right ones — the quaternion's unit norm and sign never meet a weighted average. After
each step the mean rotation is folded into ``q_ref``, ``q_ref ← q_ref ⊗ exp(δθ̄)``, and reset to 0.

The reference attitudes enter the model through the input vector, so the transition stays a
pure function: ``u = [ω (3), q_ref before (4), q_ref after (4)]``.
"""

from __future__ import annotations

import numpy as np

from quadlib.filters import ModelUKF
from quadlib.fixedwing.model import accel_model, mag_model
from quadlib.geometry.quaternion import (
    integrate_body_rate,
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_to_rotvec,
)
from quadlib.model import Model, Sensor
from quadlib.validation import as_positive

__all__ = ["ErrorStateUKF"]


def _attitude(q_ref, e):
    return quat_multiply(q_ref, quat_from_rotvec(e[:3]))


def _error_model(sigma_gyro: float, sigma_bias_walk: float) -> Model:
    def g(e, u, dt):
        omega, q_old, q_new = u[:3], u[3:7], u[7:11]
        q = integrate_body_rate(_attitude(q_old, e), omega - e[3:], dt)
        return np.concatenate([quat_to_rotvec(quat_multiply(quat_conjugate(q_new), q)), e[3:]])

    return Model(state_names=("dtheta_x", "dtheta_y", "dtheta_z", "b_p", "b_q", "b_r"),
                 input_names=("p", "q", "r", "qa0", "qa1", "qa2", "qa3", "qb0", "qb1", "qb2", "qb3"), g=g,
                 G=lambda e, u, dt: np.eye(6),  # not used: the UKF needs no Jacobian
                 Q=lambda dt: np.diag([(sigma_gyro * dt) ** 2] * 3 + [sigma_bias_walk**2 * dt] * 3),
                 name="fixed-wing error state")


class ErrorStateUKF:
    """Multiplicative UKF with the same sensors as Salmony's EKF (eqs. 13–14, corrected).

    Parameters
    ----------
    q0, b0 : initial attitude ``q_nb`` and gyro bias [rad/s]
    sigma_attitude0_rad, sigma_bias0_rad_s : initial standard deviations
    sigma_gyro_rad_s, sigma_bias_walk_rad_s_sqrt_s : process noise
    dt : step [s]
    """

    def __init__(self, q0, b0, sigma_attitude0_rad: float, sigma_bias0_rad_s: float, sigma_gyro_rad_s: float,
                 sigma_bias_walk_rad_s_sqrt_s: float, dt: float):
        P0 = np.diag([as_positive("sigma_attitude0_rad", sigma_attitude0_rad) ** 2] * 3
                     + [as_positive("sigma_bias0_rad_s", sigma_bias0_rad_s) ** 2] * 3)
        model = _error_model(as_positive("sigma_gyro_rad_s", sigma_gyro_rad_s),
                             as_positive("sigma_bias_walk_rad_s_sqrt_s", sigma_bias_walk_rad_s_sqrt_s))
        self.ukf = ModelUKF(model, np.r_[np.zeros(3), np.asarray(b0, dtype=float)], P0, as_positive("dt", dt))
        self.q_ref = np.asarray(q0, dtype=float) / np.linalg.norm(q0)

    @property
    def state(self) -> np.ndarray:
        """``[q0, q1, q2, q3, b_p, b_q, b_r]``, comparable with the EKF's state."""
        e = self.ukf.estimate
        return np.concatenate([_attitude(self.q_ref, e), e[3:]])

    @property
    def sigma(self) -> np.ndarray:
        """Standard deviations of ``[δθ, b]`` [rad, rad/s]."""
        return np.sqrt(np.diag(self.ukf.P))

    def _fold(self) -> None:
        e = self.ukf.estimate
        self.q_ref = _attitude(self.q_ref, e)
        self.ukf.x = np.r_[np.zeros(3), e[3:]]

    def predict(self, omega, dt: float) -> None:
        omega = np.asarray(omega, dtype=float)
        q_new = integrate_body_rate(self.q_ref, omega - self.ukf.estimate[3:], dt)
        self.ukf.predict(np.concatenate([omega, self.q_ref, q_new]), dt)
        self.q_ref = q_new
        self._fold()

    def update(self, accel=None, mag=None, *, omega, airspeed_m_s, accel_sigma: float, mag_sigma: float,
               declination_rad: float, inclination_rad: float, unmodelled_m_s2: float = 3.0) -> None:
        """Accelerometer and magnetometer updates; ``airspeed_m_s=None`` drops the airspeed terms
        (with ``unmodelled_m_s2`` added to the accelerometer's σ), a None sample skips its update."""
        q_ref, omega = self.q_ref.copy(), np.asarray(omega, dtype=float)
        if accel is not None:
            va = 0.0 if airspeed_m_s is None else float(airspeed_m_s)
            var = accel_sigma**2 + (unmodelled_m_s2**2 if airspeed_m_s is None else 0.0)
            sensor = Sensor(name="accel", measurement_names=("ax", "ay", "az"),
                            h=lambda e: accel_model(np.r_[_attitude(q_ref, e), e[3:]], omega, va),
                            H=lambda e: np.zeros((3, 6)), R=var * np.eye(3))
            self.ukf.update_sensor(sensor, accel)
            self._fold()
            q_ref = self.q_ref.copy()
        if mag is not None:
            sensor = Sensor(name="mag", measurement_names=("mx", "my", "mz"),
                            h=lambda e: mag_model(np.r_[_attitude(q_ref, e), e[3:]], declination_rad, inclination_rad),
                            H=lambda e: np.zeros((3, 6)), R=mag_sigma**2 * np.eye(3))
            self.ukf.update_sensor(sensor, mag)
            self._fold()
