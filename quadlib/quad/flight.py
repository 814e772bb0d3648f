"""A quadrotor flying a smooth 3D course, and what its sensors read.

The truth comes from differential flatness: given position ``p(t)`` (NED) and yaw ``ψ(t)``,
a quadrotor's thrust must point along ``a_n − g_n``, which fixes roll and pitch; body rates
follow from consecutive attitudes, and the accelerometer reads the specific force
``f_b = R_nbᵀ (a_n − g_n)``. An ideal quadrotor's thrust is along body z, so ``f_b`` has no x or
y component: the accelerometer only "sees" tilt when the vehicle does not accelerate.

Sensor noise defaults follow the course simulator the Tellex document was written for
(:class:`SensorNoise3D`, all in one place). The IMU is sampled by :func:`quadlib.sim.imu_samples`
(a flight has the attributes it reads); GPS, magnetometer and barometer here. Every random draw
comes from the ``rng`` argument.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from quadlib.constants import GRAVITY_N, earth_field_ned
from quadlib.geometry.quaternion import body_rates_between, quat_from_euler, quat_to_dcm
from quadlib.geometry.rotations import dcm_to_euler, wrap_angle
from quadlib.imu import ImuNoise
from quadlib.samples import Samples
from quadlib.sim.imu import BodyMotion
from quadlib.sim.trajectories import min_jerk
from quadlib.validation import as_finite_array, as_instance, as_positive, as_rng, as_times, as_vectors3

__all__ = ["Flight3D", "SensorNoise3D", "baro_samples", "figure_eight", "flight_from_path",
           "gps_samples", "mag_field_samples", "mag_yaw_samples", "square_course"]



@dataclass(frozen=True)
class Flight3D(BodyMotion):
    """True state of a flight sampled at ``t`` (``N`` samples, uniform step): what
    :class:`~quadlib.sim.BodyMotion` holds (``t``, ``q_nb``, ``omega_b``, ``f_b``), plus

    Attributes
    ----------
    pos, vel, acc : (N, 3) NED position [m], velocity [m/s], acceleration [m/s²]
    euler : (N, 3) roll, pitch, yaw [rad] (yaw wrapped to (−π, π])
    """

    pos: np.ndarray
    vel: np.ndarray
    acc: np.ndarray
    euler: np.ndarray


def flight_from_path(t, pos, vel, acc, yaw) -> Flight3D:
    """Attitude, body rates and specific force of a quadrotor following ``pos(t)`` with ``yaw(t)``.

    Body z points against the thrust, ``b3 = −(a − g_n)/|a − g_n|``; body x is the heading
    direction projected perpendicular to it.
    """
    t = as_times("t", t)
    pos, vel, acc = (as_vectors3(name, a) for name, a in (("pos", pos), ("vel", vel), ("acc", acc)))
    yaw = as_finite_array("yaw", yaw, ndim=1)
    for name, a in (("pos", pos), ("vel", vel), ("acc", acc), ("yaw", yaw)):
        if a.shape[0] != t.size or a.ndim != (1 if name == "yaw" else 2):
            raise ValueError(f"{name}: expected one row per time ({t.size}), got shape {a.shape}")
    thrust = acc - GRAVITY_N
    b3 = -thrust / np.linalg.norm(thrust, axis=1, keepdims=True)
    heading = np.column_stack([np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)])
    b2 = np.cross(b3, heading)
    b2 /= np.linalg.norm(b2, axis=1, keepdims=True)
    b1 = np.cross(b2, b3)
    R = np.stack([b1, b2, b3], axis=-1)  # columns are the body axes in NED
    roll, pitch, yaw_w = dcm_to_euler(R)
    q = quat_from_euler(roll, pitch, yaw_w)
    # sign continuity, then the constant rate that turns q[k] into q[k+1]
    flips = np.cumprod(np.where(np.sum(q[1:] * q[:-1], axis=1) < 0.0, -1.0, 1.0))
    q[1:] *= flips[:, None]
    dt = t[1] - t[0]
    omega = body_rates_between(q, dt)
    f_b = np.einsum("nji,nj->ni", R, thrust)
    return Flight3D(t=t, pos=pos, vel=vel, acc=acc, q_nb=q, euler=np.column_stack([roll, pitch, yaw_w]),
                    omega_b=omega, f_b=f_b)


def _time_grid(duration_s: float, rate_hz: float) -> np.ndarray:
    n = int(round(duration_s * rate_hz))
    return np.arange(n + 1) / rate_hz


def square_course(side_m: float = 10.0, altitude_m: float = 3.0, leg_s: float = 5.0, turn_s: float = 2.0,
                  rate_hz: float = 500.0) -> Flight3D:
    """A square flown north, east, south, west, stopping at each corner to turn 90° right.

    Each leg and each turn is a minimum-jerk move (rest to rest). The peak acceleration of a leg
    is ``5.77 side / leg_s²`` (2.3 m/s², a 13° tilt, with the defaults). The yaw goes 0 → 2π
    and crosses ±π during the third turn.
    """
    side, alt = as_positive("side_m", side_m), as_positive("altitude_m", altitude_m)
    leg, turn, rate = as_positive("leg_s", leg_s), as_positive("turn_s", turn_s), as_positive("rate_hz", rate_hz)
    t = _time_grid(4 * (leg + turn), rate)
    corners = np.array([[0, 0], [side, 0], [side, side], [0, side], [0, 0]], dtype=float)
    pos, vel, acc = np.zeros((t.size, 3)), np.zeros((t.size, 3)), np.zeros((t.size, 3))
    pos[:, 2] = -alt
    yaw = np.zeros(t.size)
    for i in range(4):
        t_leg, t_turn = i * (leg + turn), i * (leg + turn) + leg
        on_leg = (t >= t_leg) & (t < t_turn)
        s0, s1, s2 = min_jerk((t[on_leg] - t_leg) / leg)
        delta = corners[i + 1] - corners[i]
        pos[on_leg, :2] = corners[i] + np.outer(s0, delta)
        vel[on_leg, :2] = np.outer(s1 / leg, delta)
        acc[on_leg, :2] = np.outer(s2 / leg**2, delta)
        yaw[on_leg] = i * np.pi / 2
        after = t >= t_turn
        pos[after, :2] = corners[i + 1]
        yaw[after] = i * np.pi / 2 + min_jerk((t[after] - t_turn) / turn)[0] * np.pi / 2
    return flight_from_path(t, pos, vel, acc, yaw)


def straight_course(length_m: float = 30.0, duration_s: float = 30.0, altitude_m: float = 3.0,
                    rate_hz: float = 500.0) -> Flight3D:
    """Rest to rest ``length_m`` north in ``duration_s`` (one minimum-jerk move), nose north: the
    flight down a corridor."""
    length, duration = as_positive("length_m", length_m), as_positive("duration_s", duration_s)
    alt, rate = as_positive("altitude_m", altitude_m), as_positive("rate_hz", rate_hz)
    t = _time_grid(duration, rate)
    s0, s1, s2 = min_jerk(t / duration)
    pos, vel, acc = np.zeros((t.size, 3)), np.zeros((t.size, 3)), np.zeros((t.size, 3))
    pos[:, 0], vel[:, 0], acc[:, 0] = length * s0, length * s1 / duration, length * s2 / duration**2
    pos[:, 2] = -alt
    return flight_from_path(t, pos, vel, acc, np.zeros(t.size))


def figure_eight(width_m: float = 20.0, period_s: float = 20.0, altitude_m: float = 3.0, duration_s: float = 20.0,
                 rate_hz: float = 500.0) -> Flight3D:
    """A horizontal figure eight ``x = (w/2) sin ωt, y = (w/4) sin 2ωt``, nose along the velocity."""
    w, period = as_positive("width_m", width_m), as_positive("period_s", period_s)
    alt, rate = as_positive("altitude_m", altitude_m), as_positive("rate_hz", rate_hz)
    t = _time_grid(as_positive("duration_s", duration_s), rate)
    om = 2 * np.pi / period
    a, b = w / 2, w / 4
    pos = np.column_stack([a * np.sin(om * t), b * np.sin(2 * om * t), np.full(t.size, -alt)])
    vel = np.column_stack([a * om * np.cos(om * t), 2 * b * om * np.cos(2 * om * t), np.zeros(t.size)])
    acc = np.column_stack([-a * om**2 * np.sin(om * t), -4 * b * om**2 * np.sin(2 * om * t), np.zeros(t.size)])
    yaw = np.unwrap(np.arctan2(vel[:, 1], vel[:, 0]))
    return flight_from_path(t, pos, vel, acc, yaw)


@dataclass(frozen=True)
class SensorNoise3D(ImuNoise):
    """Sensor rates and noise of the 3D simulator (σ per sample; the course simulator's values).

    IMU samples come at the flight's rate (500 Hz by default); ``mag_sigma`` is per axis of the
    three-axis magnetometer [G]. Besides :class:`~quadlib.imu.ImuNoise`'s fields: GPS position and
    velocity, magnetometer heading, barometer (rates [Hz] and σ), the field's strength [G] and dip [rad].
    """

    gyro_sigma_rad_s: float = 0.5
    accel_sigma_m_s2: tuple = (0.5, 0.5, 1.5)
    mag_sigma: float = 0.01
    gps_rate_hz: float = 10.0
    gps_pos_sigma_m: tuple = (0.7, 0.7, 2.0)
    gps_vel_sigma_m_s: tuple = (0.1, 0.1, 0.3)
    mag_rate_hz: float = 100.0
    mag_yaw_sigma_rad: float = 0.1
    field_gauss: float = 0.5
    inclination_rad: float = field(default=float(np.radians(60.0)))
    baro_rate_hz: float = 25.0
    baro_sigma_m: float = 0.5

    FIELDS = ImuNoise.FIELDS | {"gps_rate_hz": "positive", "gps_pos_sigma_m": "positive or 3",
                                "gps_vel_sigma_m_s": "positive or 3", "mag_rate_hz": "positive",
                                "mag_yaw_sigma_rad": "positive", "field_gauss": "positive", "inclination_rad": "finite",
                                "baro_rate_hz": "positive", "baro_sigma_m": "positive"}


def _every(flight: Flight3D, rate_hz: float) -> np.ndarray:
    step = int(round(1.0 / (as_positive("rate_hz", rate_hz) * flight.dt)))
    if step < 1:
        raise ValueError(f"rate_hz: expected at most the flight's rate {1 / flight.dt:g} Hz, got {rate_hz}")
    return np.arange(0, flight.t.size, step)


def gps_samples(flight: Flight3D, noise: SensorNoise3D, rng) -> Samples:
    """GPS position and velocity ``[x, y, z, ẋ, ẏ, ż]`` (NED) at ``gps_rate_hz``."""
    flight, noise = as_instance("flight", flight, Flight3D), as_instance("noise", noise, SensorNoise3D)
    k = _every(flight, noise.gps_rate_hz)
    sigma = np.concatenate([noise.gps_pos_sigma_m, noise.gps_vel_sigma_m_s]).astype(float)
    truth = np.hstack([flight.pos[k], flight.vel[k]])
    return Samples(flight.t[k], truth + as_rng(rng).standard_normal(truth.shape) * sigma)


def mag_yaw_samples(flight: Flight3D, noise: SensorNoise3D, rng) -> Samples:
    """Heading from magnetic north [rad], wrapped to (−π, π], at ``mag_rate_hz`` (Tellex eq. 56)."""
    flight, noise = as_instance("flight", flight, Flight3D), as_instance("noise", noise, SensorNoise3D)
    k = _every(flight, noise.mag_rate_hz)
    yaw = flight.euler[k, 2] + as_rng(rng).standard_normal(k.size) * noise.mag_yaw_sigma_rad
    return Samples(flight.t[k], wrap_angle(yaw)[:, None])


def mag_field_samples(flight: Flight3D, noise: SensorNoise3D, rng) -> Samples:
    """Three-axis magnetometer [gauss] in the body frame; the field points north and down (dip)."""
    flight, noise = as_instance("flight", flight, Flight3D), as_instance("noise", noise, SensorNoise3D)
    k = _every(flight, noise.mag_rate_hz)
    m_b = np.einsum("nji,j->ni", quat_to_dcm(flight.q_nb[k]), earth_field_ned(noise.field_gauss, noise.inclination_rad))
    return Samples(flight.t[k], m_b + as_rng(rng).standard_normal(m_b.shape) * noise.mag_sigma)


def baro_samples(flight: Flight3D, noise: SensorNoise3D, rng) -> Samples:
    """Barometric altitude above the start [m] (``−z``) at ``baro_rate_hz``."""
    flight, noise = as_instance("flight", flight, Flight3D), as_instance("noise", noise, SensorNoise3D)
    k = _every(flight, noise.baro_rate_hz)
    return Samples(flight.t[k], (-flight.pos[k, 2] + as_rng(rng).standard_normal(k.size) * noise.baro_sigma_m)[:, None])
