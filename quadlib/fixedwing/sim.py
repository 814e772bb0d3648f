"""A fixed-wing flight for Salmony's attitude EKF: straight flight, coordinated turns, a climb.

The aircraft flies along its body x axis at airspeed ``V`` (no sideslip, no angle of attack, the
document's assumption), so the truth follows from an attitude profile and a speed profile: body
rates from consecutive attitudes, and the accelerometer's specific force from eq. (1),
``f_b = V̇ e_x + ω × [V, 0, 0] − R(q)ᵀ g_n``. Turns are coordinated: the bank angle is
``atan(V ψ̇ / g)``, so the specific force has (almost) no sideways part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.constants import G0, GRAVITY_N, earth_field_ned
from quadlib.fixedwing.model import FixedWingNoise
from quadlib.geometry.quaternion import body_rates_between, quat_from_euler, quat_multiply, quat_to_dcm, quat_to_euler
from quadlib.imu import ImuLog
from quadlib.sim.imu import BodyMotion, imu_samples
from quadlib.sim.trajectories import min_jerk
from quadlib.validation import as_count, as_finite_number, as_instance, as_positive, as_rng

__all__ = ["FixedWingFlight", "aileron_roll", "fixedwing_flight", "fixedwing_samples"]



@dataclass(frozen=True)
class FixedWingFlight(BodyMotion):
    """Truth at ``t`` (uniform step): what :class:`~quadlib.sim.BodyMotion` holds, plus roll, pitch,
    yaw ``euler`` (N, 3) [rad] and ``airspeed`` (N,) [m/s]."""

    euler: np.ndarray
    airspeed: np.ndarray


def _blend(t, changes):
    """A profile that moves between values with minimum-jerk blends: ``changes`` = [(t0, t1, Δ), …]."""
    out = np.zeros_like(t)
    for t0, t1, delta in changes:
        out += delta * min_jerk((t - t0) / (t1 - t0))[0]
    return out


def fixedwing_flight(rate_hz: float = 100.0, airspeed_m_s: float = 20.0) -> FixedWingFlight:
    """70 s: straight and level, a right turn (90°), a 5° climb, a left turn (180°), a speed
    change from ``airspeed_m_s`` to ``airspeed_m_s + 4`` and back, straight flight."""
    rate, v0 = as_positive("rate_hz", rate_hz), as_positive("airspeed_m_s", airspeed_m_s)
    t = np.arange(int(70 * rate) + 1) / rate
    airspeed = v0 + _blend(t, [(40.0, 44.0, 4.0), (55.0, 59.0, -4.0)])
    yaw = _blend(t, [(8.0, 20.0, np.pi / 2), (32.0, 50.0, -np.pi)])
    yaw_rate = np.gradient(yaw, t)
    roll = np.arctan(airspeed * yaw_rate / G0)  # coordinated
    pitch = _blend(t, [(22.0, 24.0, np.radians(5.0)), (28.0, 30.0, -np.radians(5.0))]) + np.radians(2.0)
    return _flight(t, quat_from_euler(roll, pitch, yaw), airspeed)


def _flight(t, q, airspeed) -> FixedWingFlight:
    """The flight along body x at ``airspeed`` with attitudes ``q``: rates, specific force (eq. 1)."""
    omega = body_rates_between(q, t[1] - t[0])
    v_b = np.column_stack([airspeed, np.zeros((t.size, 2))])
    f_b = (np.column_stack([np.gradient(airspeed, t), np.zeros((t.size, 2))]) + np.cross(omega, v_b)
           - np.einsum("nji,j->ni", quat_to_dcm(q), GRAVITY_N))
    return FixedWingFlight(t=t, q_nb=q, euler=np.column_stack(quat_to_euler(q)), omega_b=omega, f_b=f_b,
                           airspeed=airspeed)


def aileron_roll(flight: FixedWingFlight, start_s: float, rate_rad_s: float, turns: int = 1) -> FixedWingFlight:
    """``flight`` with ``turns`` full rolls about body x at a constant ``rate_rad_s`` added from
    ``start_s`` on: the attitude becomes ``q ⊗ exp(φ(t) e_x)``, the path and airspeed stay."""
    if not isinstance(flight, FixedWingFlight):
        raise TypeError(f"flight: expected a FixedWingFlight, got {type(flight).__name__}")
    rate, start_s = as_positive("rate_rad_s", rate_rad_s), as_finite_number("start_s", start_s)
    turns = as_count("turns", turns)
    if not flight.t[0] <= start_s < flight.t[-1]:
        raise ValueError(f"start_s: expected a time within the flight [{flight.t[0]}, {flight.t[-1]}) s, got {start_s}")
    angle = np.clip((flight.t - start_s) * rate, 0.0, 2 * np.pi * turns)
    roll = np.column_stack([np.cos(angle / 2), np.sin(angle / 2), np.zeros((angle.size, 2))])
    return _flight(flight.t, quat_multiply(flight.q_nb, roll), flight.airspeed)


def fixedwing_samples(flight: FixedWingFlight, noise: FixedWingNoise, rng) -> ImuLog:
    """Sensor samples of ``flight``: gyro with bias and bias random walk, accelerometer, the
    magnetometer as a unit vector (declination and inclination), and pitot airspeed."""
    flight, noise = as_instance("flight", flight, FixedWingFlight), as_instance("noise", noise, FixedWingNoise)
    rng = as_rng(rng)
    log = imu_samples(flight, noise, rng, field_n=earth_field_ned(1.0, noise.inclination_rad, noise.declination_rad))
    mag = log.mag / np.linalg.norm(log.mag, axis=1, keepdims=True)
    airspeed = flight.airspeed + rng.normal(0.0, noise.airspeed_sigma_m_s, flight.t.size)
    return ImuLog(log.t, log.gyro, log.accel, mag, airspeed)
