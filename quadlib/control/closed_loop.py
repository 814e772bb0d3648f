"""Fly the quadrotor of :mod:`~quadlib.control.vehicle` with Kesten's controllers, on the true state
or on the estimates of the project's filters: the estimator in the loop.

Every control period (Kesten's 4 ms, eq. 4.5) the loop samples the IMU from the true motion (the
magnetometer every 20 ms, the barometer every 40 ms, eqs. 4.13 and 4.17; the noise of
:class:`~quadlib.attitude.AttitudeNoise`), lets the estimators take those samples, asks the
controllers for motor thrusts on the estimate, and integrates the rigid body over the period.
The estimators are the attitude-and-gyro-bias EKF of chapters 15–16 (gyro, gravity, heading) and
Kesten's altitude filter (chapter 14), each a :class:`~quadlib.ModelFilter` stepped sample by sample
by a :class:`~quadlib.stepper.FilterStepper`: the steps of :func:`~quadlib.replay.run_filter`, which
replays the logged inputs and samples (``FilterStepper.log``) to the same estimates. The filters'
time grid starts one period before the flight: at control step ``k`` each predicts with the IMU
sample just taken, then applies the samples taken at ``t_k``.
With ``estimator="truth"`` the controllers see the true state: perfect estimation, the baseline;
``"altitude"`` puts only the altitude filter in the loop.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from quadlib.attitude.altitude import altitude_model, baro_altitude_sensor
from quadlib.attitude.bias_model import attitude_bias_model
from quadlib.attitude.kesten import AttitudeNoise
from quadlib.constants import G0
from quadlib.control.controllers import AltitudePid, AttitudePid, PositionController, attitude_pid_gains
from quadlib.control.lqr import AltitudeGains, altitude_pid_gains
from quadlib.control.references import Reference
from quadlib.control.vehicle import QuadrotorParams, constants, hover_state
from quadlib.filters import LinearKF, ModelEKF
from quadlib.kernels.quaternion import dcm, normalize
from quadlib.kernels.vehicle import derivative as vehicle_derivative
from quadlib.kernels.vehicle import step as vehicle_step
from quadlib.nav.ins import GYRO_BIAS_ERRORS, InsParams, ins_baro_sensor, ins_gps_sensor
from quadlib.quad.flight import Flight3D
from quadlib.sensors import gravity_sensor, heading_sensor
from quadlib.stepper import FilterStepper, Sample
from quadlib.validation import (
    as_count,
    as_finite_array,
    as_instance,
    as_positive,
    as_rng,
    as_vector,
    check_fields,
)

__all__ = ["ClosedLoopRun", "LoopSensors", "PathRun", "fly", "fly_path"]


@dataclass(frozen=True)
class LoopSensors:
    """Sample periods [s] (Kesten eqs. 4.5, 4.13, 4.17) and noise of the sensors in the loop, and the
    filters' settings.

    Parameters
    ----------
    noise : AttitudeNoise
        Gyro, accelerometer and magnetometer noise per sample and the Earth's field (Kesten §4.2–4.4).
    imu_period_s, mag_period_s, baro_period_s : float
        The magnetometer and barometer periods must be whole multiples of the IMU's.
    baro_sigma_m : float
        Barometer noise (Kesten's variance 0.15 m², §4.5).
    gravity_sigma_m_s2 : float
        The attitude filter's trust in the accelerometer as a gravity sensor. A multirotor's
        accelerometer reads the thrust's direction, body z, whatever the tilt: it shows gravity only
        while the vehicle does not accelerate, so this must be far more than its noise (chapter 18
        sweeps it).
    gyro_bias_sigma_rad_s : float
        σ of the gyro bias the filter starts with: what is left after calibrating it on the ground.
    altitude_weight : float
        Kesten's altitude filter's gravity-state weight ``w`` (chapter 14).
    altitude_accel_sigma_m_s2 : float, optional
        The accelerometer noise the altitude filter assumes (its ``Q``); by default the true one.
        Larger trusts the barometer more: a faster, noisier estimate.
    """

    noise: AttitudeNoise = AttitudeNoise()
    imu_period_s: float = 0.004
    mag_period_s: float = 0.02
    baro_period_s: float = 0.04
    baro_sigma_m: float = float(np.sqrt(0.15))
    gravity_sigma_m_s2: float = 100.0
    gyro_bias_sigma_rad_s: float = 0.005
    altitude_weight: float = 2e-4
    altitude_accel_sigma_m_s2: float | None = None

    def __post_init__(self):
        check_fields(self, {"imu_period_s": "positive", "mag_period_s": "positive", "baro_period_s": "positive",
                            "baro_sigma_m": "positive", "gravity_sigma_m_s2": "positive",
                            "gyro_bias_sigma_rad_s": "positive", "altitude_weight": "probability",
                            "altitude_accel_sigma_m_s2": "optional positive"})
        if not isinstance(self.noise, AttitudeNoise):
            raise TypeError(f"LoopSensors.noise: expected an AttitudeNoise, got {self.noise!r}")
        for name in ("mag_period_s", "baro_period_s"):
            ratio = getattr(self, name) / self.imu_period_s
            if abs(ratio - round(ratio)) > 1e-9 or round(ratio) < 1:
                raise ValueError(f"LoopSensors.{name}: expected a whole multiple of imu_period_s "
                                 f"({self.imu_period_s:g} s), got {getattr(self, name):g} s")

    def every(self, period_s: float) -> int:
        return int(round(period_s / self.imu_period_s))


@dataclass(frozen=True)
class ClosedLoopRun:
    """One closed-loop flight, sampled every control period (``K`` steps).

    Attributes
    ----------
    t : (K,) times [s]
    state : (K, 17) true rigid-body state (:mod:`~quadlib.control.vehicle`)
    height, climb : (K,) true height and climb rate [m, m/s, up]
    height_est, climb_est : (K,) what the controller used
    q_est : (K, 4) the attitude the controller used
    s_ref : (K,) reference height; q_ref : (K, 4) reference attitude
    thrust_cmd : (K, 4) commanded motor thrusts [N] (before the motors' limits)
    steppers : dict of name ("attitude", "altitude") -> the FilterStepper of each filter in the loop
    """

    t: np.ndarray
    state: np.ndarray
    height: np.ndarray
    climb: np.ndarray
    height_est: np.ndarray
    climb_est: np.ndarray
    q_est: np.ndarray
    s_ref: np.ndarray
    q_ref: np.ndarray
    thrust_cmd: np.ndarray
    steppers: dict = field(default_factory=dict, repr=False, compare=False)


class _Filters:
    """The two estimators, stepped one IMU sample at a time from ``start_s``."""

    def __init__(self, sensors: LoopSensors, X0: np.ndarray, attitude: bool, start_s: float):
        n, dt = sensors.noise, sensors.imu_period_s
        self.steppers = {}
        if attitude:
            model = attitude_bias_model(n.gyro_sigma_rad_s, 1e-5)
            P0 = np.diag([0.02] * 3 + [sensors.gyro_bias_sigma_rad_s] * 3) ** 2
            ekf = ModelEKF(model, np.r_[X0[6:10], 0.0, 0.0, 0.0], P0, dt)
            self.steppers["attitude"] = FilterStepper(
                ekf, [gravity_sensor(sensors.gravity_sigma_m_s2), heading_sensor(0.05)], gate_probability=0.9999)
        sigma_a = n.accel_sigma_m_s2 if sensors.altitude_accel_sigma_m_s2 is None else sensors.altitude_accel_sigma_m_s2
        altitude = altitude_model(sigma_a, sensors.altitude_weight)
        kf = LinearKF(altitude, np.array([-X0[2], 0.0, G0]), np.diag([0.5, 0.1, 0.05]) ** 2, dt)
        self.steppers["altitude"] = FilterStepper(kf, [baro_altitude_sensor(sensors.baro_sigma_m)])
        for stepper in self.steppers.values():
            stepper.step(start_s)

    def step(self, t, gyro, accel, mag, baro, q_true, omega_true):
        attitude = self.steppers.get("attitude")
        if attitude is not None:
            samples = [Sample("gravity", t, accel)] + ([] if mag is None else [Sample("heading", t, [0.0], mag)])
            x, _ = attitude.step(t, gyro, samples)
            q_hat, omega_hat = x[:4], gyro - x[4:]
        else:
            q_hat, omega_hat = q_true, omega_true
        s, _ = self.steppers["altitude"].step(t, [-float(dcm(q_hat)[2] @ accel)],  # eq. (2.67)
                                              [] if baro is None else [Sample("baro", t, [baro])])
        return s[0], s[1], q_hat, omega_hat


def _read_sensors(vehicle: tuple, sensors: LoopSensors, X, thrust, k: int, rng):
    """The IMU at control step ``k`` from the true state, the magnetometer and barometer on their
    own periods (None between samples). ``vehicle``: the constants of the vehicle's parameters."""
    n = sensors.noise
    R = dcm(X[6:10])
    f_b = R.T @ (vehicle_derivative(X, thrust, *vehicle)[3:6] - np.array([0.0, 0.0, G0]))  # specific force
    gyro = X[10:13] + np.asarray(n.gyro_bias_rad_s, dtype=float) + rng.standard_normal(3) * n.gyro_sigma_rad_s
    accel = f_b + rng.standard_normal(3) * n.accel_sigma_m_s2
    mag = R.T @ n.field_n + rng.standard_normal(3) * n.mag_sigma if k % sensors.every(sensors.mag_period_s) == 0 \
        else None
    baro = -X[2] + rng.standard_normal() * sensors.baro_sigma_m if k % sensors.every(sensors.baro_period_s) == 0 \
        else None
    return gyro, accel, mag, baro


def _as_gains(gains) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    try:
        C = tuple(as_finite_array(f"attitude_gains[{i}]", g) for i, g in enumerate(gains))
    except TypeError as err:
        raise TypeError(f"attitude_gains: expected (C_p, C_i, C_d), three 3 × 3 matrices, got {gains!r}") from err
    if len(C) != 3 or any(c.shape != (3, 3) for c in C):
        raise ValueError(f"attitude_gains: expected (C_p, C_i, C_d), three 3 × 3 matrices, got shapes "
                         f"{[c.shape for c in C]}")
    return C


def fly(reference: Callable[[float], Reference], duration_s: float, params: QuadrotorParams = QuadrotorParams(), *,  # noqa: B008
        estimator: str = "truth", rng=None, sensors: LoopSensors = LoopSensors(),
        altitude_gains: AltitudeGains | None = None, attitude_gains=None, physics_steps: int = 1,
        x0=None) -> ClosedLoopRun:
    """Fly ``duration_s`` seconds from hover at the reference's first height, closed loop.

    Parameters
    ----------
    reference : callable ``t -> Reference``
    duration_s : float
    params : QuadrotorParams
    estimator : {"truth", "altitude", "filters"}
        What the controllers see: the true state; the altitude filter's height and climb rate with
        the true attitude; or the estimates of both filters.
    rng : numpy.random.Generator
        Required with a filter in the loop (sensor noise).
    sensors : LoopSensors
    altitude_gains : AltitudeGains, optional
        Default :func:`~quadlib.control.altitude_pid_gains` for ``params.mass_kg`` (Kesten's weights).
    attitude_gains : (C_p, C_i, C_d), optional
        Default :func:`~quadlib.control.attitude_pid_gains`.
    physics_steps : int
        Runge–Kutta steps per control period (one is enough at 4 ms: the fastest dynamics, the
        motors' 30 ms lag, take seven periods).
    x0 : (17,) array_like, optional
        The true start; by default hover at the reference's first height and attitude.
    """
    if not callable(reference):
        raise TypeError(f"reference: expected a callable t -> Reference, got {reference!r}")
    duration = as_positive("duration_s", duration_s)
    params = as_instance("params", params, QuadrotorParams)
    sensors = as_instance("sensors", sensors, LoopSensors)
    if estimator not in ("truth", "altitude", "filters"):
        raise ValueError(f"estimator: expected 'truth', 'altitude' or 'filters', got {estimator!r}")
    if estimator != "truth" or rng is not None:
        rng = as_rng(rng)
    physics_steps = as_count("physics_steps", physics_steps)
    gains = altitude_pid_gains(params.mass_kg) if altitude_gains is None else as_instance(
        "altitude_gains", altitude_gains, AltitudeGains)
    if not all(np.isfinite(gains)):
        raise ValueError(f"altitude_gains: expected finite gains, got {gains}")
    C = attitude_pid_gains(params) if attitude_gains is None else _as_gains(attitude_gains)
    altitude_pid, attitude_pid = AltitudePid(gains, params.hover_thrust_n), AttitudePid(*C)
    vehicle = constants(params)  # for the compiled vehicle step

    dt = sensors.imu_period_s
    K = int(round(duration / dt)) + 1
    first = reference(0.0)
    X = hover_state(params, first.s, first.q_nb) if x0 is None else np.array(as_vector("x0", x0, 17))
    if x0 is not None:
        if not X[6:10].any():
            raise ValueError(f"x0: expected a non-zero attitude quaternion in x0[6:10], got {X[6:10].tolist()}")
        X[6:10] = normalize(X[6:10])
    filters = None if estimator == "truth" else _Filters(sensors, X, estimator == "filters", start_s=-dt)
    out = {k: [] for k in ("state", "height_est", "climb_est", "q_est", "s_ref", "q_ref", "thrust_cmd")}
    thrust = X[13:17].copy()
    for k in range(K):
        t = k * dt
        ref = reference(t)
        q, omega = X[6:10], X[10:13]
        if filters is None:
            s_hat, v_hat, q_hat, omega_hat = -X[2], -X[5], q, omega
        else:
            gyro, accel, mag, baro = _read_sensors(vehicle, sensors, X, thrust, k, rng)
            s_hat, v_hat, q_hat, omega_hat = filters.step(t, gyro, accel, mag, baro, q, omega)
        thrust_z = altitude_pid.thrust(s_hat, v_hat, ref.s, ref.v, dt)
        thrust = attitude_pid.thrusts(thrust_z, q_hat, omega_hat, ref.q_nb, ref.omega, dt)
        for key, value in (("state", X), ("height_est", s_hat), ("climb_est", v_hat), ("q_est", q_hat),
                           ("s_ref", ref.s), ("q_ref", ref.q_nb), ("thrust_cmd", thrust)):
            out[key].append(np.array(value, dtype=float))
        for _ in range(physics_steps):
            X = vehicle_step(X, thrust, dt / physics_steps, *vehicle)
    state = np.array(out["state"])
    return ClosedLoopRun(t=np.arange(K) * dt, state=state, height=-state[:, 2], climb=-state[:, 5],
                         height_est=np.array(out["height_est"]), climb_est=np.array(out["climb_est"]),
                         q_est=np.array(out["q_est"]), s_ref=np.array(out["s_ref"]), q_ref=np.array(out["q_ref"]),
                         thrust_cmd=np.array(out["thrust_cmd"]), steppers={} if filters is None else filters.steppers)


@dataclass(frozen=True)
class PathRun:
    """A closed-loop flight along a path, every control period (``K`` steps).

    Attributes
    ----------
    t : (K,) times [s]
    state : (K, 17) true rigid-body state
    pos_ref, pos_est : (K, 3) the path's position and the estimate the controller used, NED [m]
    vel_est : (K, 3) estimated velocity [m/s]
    q_est : (K, 4) estimated attitude
    thrust_cmd : (K, 4) commanded motor thrusts [N]
    steppers : dict, ``{"ins": FilterStepper}`` with the filter in the loop (empty on the truth)
    """

    t: np.ndarray
    state: np.ndarray
    pos_ref: np.ndarray
    pos_est: np.ndarray
    vel_est: np.ndarray
    q_est: np.ndarray
    thrust_cmd: np.ndarray
    steppers: dict = field(default_factory=dict, repr=False, compare=False)


def fly_path(path, params: QuadrotorParams = QuadrotorParams(), *, estimator: str = "truth", rng=None,  # noqa: B008
             sensors: LoopSensors = LoopSensors(), gps_noise=None, ins_params=None,  # noqa: B008
             gps_period_s: float = 0.1) -> PathRun:
    """Fly a planned path (a :class:`~quadlib.quad.flight.Flight3D`: chapter 11's square) closed loop
    with :class:`~quadlib.control.PositionController`, on the true state or on the inertial
    navigation EKF of chapter 17 (``estimator="ins"``) stepped sample by sample: IMU every control
    period, magnetometer and barometer on ``sensors``' periods, GPS position and velocity every
    ``gps_period_s``.

    Parameters
    ----------
    path : Flight3D
        Positions, velocities, accelerations and yaw on a grid whose step divides the control period.
    params : QuadrotorParams
    estimator : {"truth", "ins"}
    rng : numpy.random.Generator
        Required with ``"ins"``.
    sensors : LoopSensors
        IMU, magnetometer and barometer noise and periods.
    gps_noise : (6,) array_like, optional
        σ of GPS north, east, down [m] and their velocities [m/s]; default chapter 11's receiver
        (0.7, 0.7, 2.0, 0.1, 0.1, 0.3).
    ins_params : InsParams, optional
        Default: the sensors' noise, GPS as above, the barometer for the height.
    gps_period_s : float
    """
    path = as_instance("path", path, Flight3D)
    params = as_instance("params", params, QuadrotorParams)
    sensors = as_instance("sensors", sensors, LoopSensors)
    if estimator not in ("truth", "ins"):
        raise ValueError(f"estimator: expected 'truth' or 'ins', got {estimator!r}")
    if estimator == "ins" or rng is not None:
        rng = as_rng(rng)
    dt = sensors.imu_period_s
    ratio = dt / path.dt
    if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
        raise ValueError(f"path: expected a time step that divides the control period {dt:g} s, got {path.dt:g} s")
    every_path = int(round(ratio))
    gps_every = int(round(as_positive("gps_period_s", gps_period_s) / dt))
    if gps_every < 1 or abs(gps_every * dt - gps_period_s) > 1e-9:
        raise ValueError(f"gps_period_s: expected a whole multiple of the control period {dt:g} s, got {gps_period_s}")
    gps_sigma = as_vector("gps_noise", (0.7, 0.7, 2.0, 0.1, 0.1, 0.3) if gps_noise is None else gps_noise, 6)
    if np.any(gps_sigma <= 0):
        raise ValueError(f"gps_noise: expected positive σ, got {gps_sigma.tolist()}")
    n = sensors.noise
    if ins_params is None:
        ins_params = InsParams(gyro_sigma_rad_s=n.gyro_sigma_rad_s, accel_sigma_m_s2=0.3,
                               gps_pos_sigma_m=tuple(gps_sigma[:3]), gps_vel_sigma_m_s=tuple(gps_sigma[3:]),
                               use_gps_height=False, baro_sigma_m=sensors.baro_sigma_m, heading_sigma_rad=0.05)
    ins_params = as_instance("ins_params", ins_params, InsParams)

    C = attitude_pid_gains(params)
    controller = PositionController(AttitudePid(*C), params.mass_kg)
    vehicle = constants(params)  # for the compiled vehicle step
    K = (path.t.size - 1) // every_path + 1
    yaw = np.unwrap(path.euler[:, 2])
    X = hover_state(params, -path.pos[0, 2], path.q_nb[0])
    X[0:3] = path.pos[0]
    stepper = None
    if estimator == "ins":
        x0 = np.concatenate([X[6:10], X[3:6], X[0:3], np.zeros(6)])
        P0 = ins_params.initial_covariance(gps_sigma[:3], gps_sigma[3:])
        ekf = ModelEKF(ins_params.model(), x0, P0, dt)
        gps_sensor = ins_gps_sensor(gps_sigma[:3], gps_sigma[3:], use_height=False)
        heading = heading_sensor(ins_params.heading_sigma_rad, dim_x=16, gyro_bias_errors=GYRO_BIAS_ERRORS)
        stepper = FilterStepper(ekf, [gps_sensor, ins_baro_sensor(ins_params.baro_sigma_m), heading],
                                gate_probability=ins_params.gate_probability)
    out = {k: [] for k in ("state", "pos_ref", "pos_est", "vel_est", "q_est", "thrust_cmd")}
    thrust = X[13:17].copy()
    for k in range(K):
        j = k * every_path
        if stepper is None:
            p_hat, v_hat, q_hat, omega_hat = X[0:3], X[3:6], X[6:10], X[10:13]
        else:
            t = k * dt
            gyro, accel, mag, baro = _read_sensors(vehicle, sensors, X, thrust, k, rng)
            samples = []
            if k % gps_every == 0:
                fix = np.concatenate([X[0:3], X[3:6]]) + rng.standard_normal(6) * gps_sigma
                samples.append(Sample("gps", t, fix[[0, 1, 3, 4, 5]]))
            if baro is not None:
                samples.append(Sample("baro", t, [baro]))  # heights about the origin
            if mag is not None:
                samples.append(Sample("heading", t, [0.0], mag))
            x, _ = stepper.step(t, np.concatenate([gyro, accel]) if k else None, samples)
            p_hat, v_hat, q_hat, omega_hat = x[7:10], x[4:7], x[0:4], gyro - x[10:13]
        thrust = controller.thrusts(p_hat, v_hat, q_hat, omega_hat, path.pos[j], path.vel[j], path.acc[j], yaw[j],
                                    path.omega_b[j], dt)
        for key, value in (("state", X), ("pos_ref", path.pos[j]), ("pos_est", p_hat), ("vel_est", v_hat),
                           ("q_est", q_hat), ("thrust_cmd", thrust)):
            out[key].append(np.array(value, dtype=float))
        X = vehicle_step(X, thrust, dt, *vehicle)
    return PathRun(t=np.arange(K) * dt, **{k: np.array(v) for k, v in out.items()},
                   steppers={} if stepper is None else {"ins": stepper})
