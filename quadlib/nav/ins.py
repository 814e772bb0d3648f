"""An inertial navigation system: one error-state EKF over attitude, velocity, position and the IMU's biases.

What an autopilot runs (PX4's EKF2, ArduPilot's EKF3), reduced to its core. The IMU drives the
prediction — the gyro turns the attitude, the accelerometer, turned into the earth frame, changes
the velocity — and GPS, the barometer and the magnetometer correct it.

State ``x`` (16): ``[q_nb (4), v (3) NED m/s, p (3) NED m, b_g (3) rad/s, b_a (3) m/s²]``, quaternion
first as in EKF2. Error ``δx`` (15): ``[δθ, δv, δp, δb_g, δb_a]`` with ``q ⊗ exp(δθ)`` (a small body
rotation) and plain differences for the rest. Input ``u = [ω_m (3) rad/s, f_m (3) m/s²]``: one gyro and
accelerometer sample (or the mean of a block of them). One step of length ``Δt``, with
``ω = ω_m − b_g``, ``f = f_m − b_a`` and ``R = R(q)`` at the start of the step:

.. math::

    q^+ = q \\otimes \\exp(\\omega\\,\\Delta t), \\quad a = R f + g_n, \\quad
    v^+ = v + a\\,\\Delta t, \\quad p^+ = p + v\\,\\Delta t + \\tfrac12 a\\,\\Delta t^2

Its error Jacobian (``[f]×`` the cross-product matrix; the attitude rows are those of the
attitude-and-bias model, :func:`~quadlib.attitude.bias_model.gyro_error_jacobians`):

.. math::

    \\frac{\\partial \\delta v^+}{\\partial \\delta\\theta} = -\\Delta t\\, R [f]_\\times, \\quad
    \\frac{\\partial \\delta v^+}{\\partial \\delta b_a} = -\\Delta t\\, R, \\quad
    \\frac{\\partial \\delta p^+}{\\partial(\\delta\\theta, \\delta b_a)} =
    \\tfrac{\\Delta t}{2} \\frac{\\partial \\delta v^+}{\\partial(\\delta\\theta, \\delta b_a)}, \\quad
    \\frac{\\partial \\delta p^+}{\\partial \\delta v} = \\Delta t\\, I

(``R exp([δθ]×) f ≈ R f − R [f]× δθ``: a tilt error leaks gravity into the horizontal acceleration,
which is how GPS velocity corrects roll and pitch.) Lever arms (GPS antenna and IMU apart) and the
earth's rotation are left out: over a 70 s flight with the antenna a few centimetres from the IMU
both are far below the GPS noise.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from quadlib.attitude.checks import SensorChecks, plausible_mag
from quadlib.constants import GRAVITY_N
from quadlib.engine.kernel import Kernel, linear_kernels
from quadlib.filters import ModelEKF
from quadlib.geometry.quaternion import quat_multiply, quat_to_dcm
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog
from quadlib.kernels import attitude as attitude_maths
from quadlib.kernels import ins as ins_maths
from quadlib.model import Model, Sensor
from quadlib.plausibility import check_gps_metres, check_imu_units, check_mag_frame, warn_unused
from quadlib.replay import FilterRun, rts_smooth, run_filter
from quadlib.samples import Measurements, Samples
from quadlib.sensors import heading_sensor
from quadlib.validation import (
    as_angle,
    as_bool,
    as_count,
    as_finite_array,
    as_finite_number,
    as_instance,
    as_positive,
    as_vector,
    check_fields,
)

__all__ = ["ERROR_NAMES", "INPUT_NAMES", "LAYOUT", "STATE_NAMES", "InsParams", "estimate_ins", "imu_blocks",
           "ins_baro_sensor", "ins_gps_sensor", "ins_initial_state", "ins_model"]

STATE_NAMES = ("q0", "q1", "q2", "q3", "vn [m/s]", "ve [m/s]", "vd [m/s]", "pn [m]", "pe [m]", "pd [m]",
               "bg_x [rad/s]", "bg_y [rad/s]", "bg_z [rad/s]", "ba_x [m/s2]", "ba_y [m/s2]", "ba_z [m/s2]")
ERROR_NAMES = ("dtheta_x", "dtheta_y", "dtheta_z", "dvn", "dve", "dvd", "dpn", "dpe", "dpd",
               "dbg_x", "dbg_y", "dbg_z", "dba_x", "dba_y", "dba_z")
INPUT_NAMES = ("p [rad/s]", "q [rad/s]", "r [rad/s]", "fx [m/s2]", "fy [m/s2]", "fz [m/s2]")
Q_, V, P, BG, BA = slice(0, 4), slice(4, 7), slice(7, 10), slice(10, 13), slice(13, 16)  # in x
GYRO_BIAS_ERRORS = (9, 10, 11)  # in δx
LAYOUT = {"q": Q_, "v": V, "p": P, "gyro_bias": BG, "accel_bias": BA}  # the parts of x, for FilterRun.layout


# the kernels both the readable filter and the compiled engine call (quadlib.kernels.ins; the error's
# ⊞, ⊟, ∂⊞/∂δ and the normalisation are the attitude model's: the quaternion first, the rest added)
_add_error = Kernel("state_add", attitude_maths.attitude_bias_add)
_error_between = Kernel("residual_x", attitude_maths.attitude_bias_difference)
_add_jacobian = Kernel("add_jacobian", attitude_maths.attitude_bias_add_jacobian)
_normalized = Kernel("normalize", attitude_maths.normalize_quaternion)
_step = Kernel("g", ins_maths.strapdown_step, GRAVITY_N)
_error_jacobian = Kernel("G", ins_maths.strapdown_error_jacobian)


def ins_model(gyro_sigma_rad_s: float, accel_sigma_m_s2: float, gyro_bias_walk_rad_s_sqrt_s: float,
              accel_bias_walk_m_s2_sqrt_s: float) -> Model:
    """The inertial navigation model (module documentation) with white input noise.

    ``gyro_sigma_rad_s`` and ``accel_sigma_m_s2`` (one σ, or one per axis) are the σ of one input
    sample; over a step they enter the attitude as ``σ_g Δt`` and the velocity as ``σ_a Δt`` (and the position as
    ``σ_a Δt²/2``, fully correlated with it). The biases walk by ``σ √Δt`` per step.
    """
    sg = as_positive("gyro_sigma_rad_s", gyro_sigma_rad_s)
    sa = as_finite_array("accel_sigma_m_s2", accel_sigma_m_s2)
    if sa.shape not in ((), (1,), (3,)) or np.any(sa <= 0):
        raise ValueError(f"accel_sigma_m_s2: expected one positive σ or three (x, y, z), got {accel_sigma_m_s2!r}")
    sa = np.broadcast_to(sa, (3,))
    sbg = as_positive("gyro_bias_walk_rad_s_sqrt_s", gyro_bias_walk_rad_s_sqrt_s)
    sba = as_positive("accel_bias_walk_m_s2_sqrt_s", accel_bias_walk_m_s2_sqrt_s)

    Q = Kernel("Q", ins_maths.strapdown_noise, [sg, *sa, sbg, sba])  # per body axis (isotropic: the same in NED)
    return Model(state_names=STATE_NAMES, input_names=INPUT_NAMES, g=_step, G=_error_jacobian, Q=Q,
                 error_names=ERROR_NAMES, state_add=_add_error, residual_x=_error_between, add_jacobian=_add_jacobian,
                 normalize=_normalized, name="inertial navigation, error state")


def ins_gps_sensor(pos_sigma_m, vel_sigma_m_s, use_height: bool = True, reset_after_s: float | None = 1.0) -> Sensor:
    """GPS position and velocity, NED: ``h(x) = [p, v]``; position and velocity gated apart, each
    reset after ``reset_after_s`` of rejection (as :func:`quadlib.quad.quad3d_gps_sensor`).

    ``use_height=False`` leaves the GPS height out (5 components: north, east and the velocity):
    the barometer is then the height reference, as in PX4's default.
    """
    sigma = np.concatenate([as_vector("pos_sigma_m", pos_sigma_m, 3), as_vector("vel_sigma_m_s", vel_sigma_m_s, 3)])
    if np.any(sigma <= 0):
        raise ValueError(f"pos_sigma_m, vel_sigma_m_s: expected positive values, got {sigma.tolist()}")
    use_height = as_bool("use_height", use_height)
    rows = [0, 1, 2, 3, 4, 5] if use_height else [0, 1, 3, 4, 5]
    A = np.zeros((len(rows), 16))
    A[np.arange(len(rows)), np.r_[P, V][rows]] = 1.0  # each component measures one state
    h, H = linear_kernels(A)
    names = np.array(["pn [m]", "pe [m]", "pd [m]", "vn [m/s]", "ve [m/s]", "vd [m/s]"])[rows]
    n_pos = 3 if use_height else 2
    return Sensor(name="gps", measurement_names=tuple(names), h=h, H=H,
                  R=np.diag(sigma[rows] ** 2), groups=(tuple(range(n_pos)), tuple(range(n_pos, len(rows)))),
                  reset_after_s=reset_after_s)


def ins_baro_sensor(sigma_m: float) -> Sensor:
    """Barometric height above the origin [m]: ``h(x) = −p_d``."""
    A = np.zeros((1, 16))
    A[0, 9] = -1.0
    h, H = linear_kernels(A)
    return Sensor(name="baro", measurement_names=("height [m]",), h=h, H=H,
                  R=np.full((1, 1), as_positive("sigma_m", sigma_m) ** 2))


@dataclass(frozen=True)
class InsParams:
    """Parameters of :func:`estimate_ins`, each with its unit. The defaults suit a small multirotor
    with a MEMS IMU and a consumer GPS receiver; chapter 17 measures them on a real flight.

    Parameters
    ----------
    gyro_sigma_rad_s : float
        White noise of one gyro sample at the log's rate [rad/s] (with the motors running,
        vibration included). Averaging ``decimate`` samples divides it by √decimate, as for:
    accel_sigma_m_s2 : float or (3,) tuple
        White noise of one accelerometer sample [m/s²], one value or one per body axis.
    gyro_bias_walk_rad_s_sqrt_s, accel_bias_walk_m_s2_sqrt_s : float
        Random walk of the biases [unit/√s].
    gps_pos_sigma_m, gps_vel_sigma_m_s : (3,) tuples
        GPS noise per NED axis.
    use_gps_height : bool
        Fuse the GPS height; False leaves the height to the barometer.
    baro_sigma_m : float
        Barometer noise [m].
    heading_sigma_rad : float
        Noise of the magnetometer's heading [rad].
    heading_tilt_aware : bool
        The heading update's two forms (:func:`quadlib.attitude.heading_sensor`): False corrects
        the heading about the vertical and ignores that a tilt error also turns the measured
        heading; True puts that into the innovation's variance and corrects the turn about body z
        only. Chapter 17 compares them: True is consistent on the simulated square, False agrees
        better with the autopilot on the real flight.
    gps_delay_s : float
        How long a fix is old when it is logged [s]: each fix is applied at its time minus this
        (PX4's ``EKF2_GPS_DELAY``). Replaying a log, the filter can simply apply it earlier.
    gate_probability : float or None
        χ² gate on every update (:func:`quadlib.run_filter`); GPS groups reset after 1 s rejected.
    initial_tilt_sigma_rad, initial_heading_sigma_rad : float
        σ of the first attitude (from the accelerometer and magnetometer).
    initial_gyro_bias_sigma_rad_s, initial_accel_bias_sigma_m_s2 : float
        σ of the biases at the start (both start at zero).
    """

    gyro_sigma_rad_s: float = 0.02
    accel_sigma_m_s2: float = 0.5
    gyro_bias_walk_rad_s_sqrt_s: float = 1e-4
    accel_bias_walk_m_s2_sqrt_s: float = 1e-3
    gps_pos_sigma_m: tuple = (0.7, 0.7, 2.0)
    gps_vel_sigma_m_s: tuple = (0.1, 0.1, 0.3)
    use_gps_height: bool = True
    baro_sigma_m: float = 0.5
    heading_sigma_rad: float = 0.05
    heading_tilt_aware: bool = False
    gps_delay_s: float = 0.0
    gate_probability: float | None = 0.9999
    initial_tilt_sigma_rad: float = 0.05
    initial_heading_sigma_rad: float = 0.2
    initial_gyro_bias_sigma_rad_s: float = 0.02
    initial_accel_bias_sigma_m_s2: float = 0.2

    def __post_init__(self):
        check_fields(self, {"gyro_sigma_rad_s": "positive", "accel_sigma_m_s2": "positive or 3",
                            "gyro_bias_walk_rad_s_sqrt_s": "positive", "accel_bias_walk_m_s2_sqrt_s": "positive",
                            "gps_pos_sigma_m": "positive or 3", "gps_vel_sigma_m_s": "positive or 3",
                            "baro_sigma_m": "positive", "heading_sigma_rad": "positive", "gps_delay_s": "nonnegative",
                            "gate_probability": "optional probability", "initial_tilt_sigma_rad": "positive",
                            "initial_heading_sigma_rad": "positive", "initial_gyro_bias_sigma_rad_s": "positive",
                            "initial_accel_bias_sigma_m_s2": "positive", "use_gps_height": "bool",
                            "heading_tilt_aware": "bool"})

    def noise(self, decimate: int = 1) -> tuple[float, np.ndarray, float, float]:
        """The arguments of :func:`ins_model` for inputs that average ``decimate`` IMU samples: the
        gyro's σ, the accelerometer's (3,) σ (both divided by √decimate), the two bias walks."""
        decimate = as_count("decimate", decimate)  # IMU samples per filter step
        root = float(np.sqrt(decimate))
        accel = np.broadcast_to(np.asarray(self.accel_sigma_m_s2, dtype=float) / root, (3,)).copy()
        return (self.gyro_sigma_rad_s / root, accel, self.gyro_bias_walk_rad_s_sqrt_s,
                self.accel_bias_walk_m_s2_sqrt_s)

    def model(self, decimate: int = 1) -> Model:
        """The INS model for inputs that average ``decimate`` IMU samples."""
        return ins_model(*self.noise(decimate))

    def initial_covariance(self, position_sigma_m, velocity_sigma_m_s) -> np.ndarray:
        """``P0`` over ``[δθ, δv, δp, δb_g, δb_a]``: the tilt's and heading's σ (the heading about
        body z, a fair stand-in for the earth's vertical at small tilts), and the first fix's σ."""
        sigma = np.concatenate([[self.initial_tilt_sigma_rad] * 2 + [self.initial_heading_sigma_rad],
                                as_vector("velocity_sigma_m_s", velocity_sigma_m_s, 3),
                                as_vector("position_sigma_m", position_sigma_m, 3),
                                [self.initial_gyro_bias_sigma_rad_s] * 3, [self.initial_accel_bias_sigma_m_s2] * 3])
        return np.diag(sigma**2)


def imu_blocks(log: ImuLog, decimate: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """The INS's time grid and inputs ``(t, u)``: ``u = [gyro, accel]`` averaged over blocks of
    ``decimate`` samples (a block holds from its first sample's time to the next block's), the
    last incomplete block dropped. A block with a missing sample is missing (NaN; held by
    :func:`~quadlib.run_filter`)."""
    log = as_instance("log", log, ImuLog)
    n = len(log)
    decimate = as_count("decimate", decimate, high=n // 2)  # at least two blocks
    m = n // decimate
    u = np.hstack([log.gyro, log.accel])[: m * decimate].reshape(m, decimate, 6).mean(axis=1)
    return log.t[: m * decimate : decimate].copy(), u


def _first_field(mag: np.ndarray, rows: int) -> np.ndarray | None:
    """The mean magnetometer reading over the first ``rows`` rows, or, if they hold none, over the
    first ``rows`` readings wherever they come; None without any reading."""
    first = mag[:rows][np.isfinite(mag[:rows]).all(axis=1)]
    if len(first):
        return first.mean(axis=0)
    readings = mag[np.isfinite(mag).all(axis=1)]
    return readings[:rows].mean(axis=0) if len(readings) else None


def ins_initial_state(log: ImuLog, position, velocity, declination_rad: float = 0.0, n_average: int = 20) -> np.ndarray:
    """``x0``: the attitude from the mean of the first ``n_average`` accelerometer and magnetometer
    samples (Kesten eqs. 2.2–2.5, turned by the declination), the given position and velocity, biases
    zero. Without a magnetometer (or without a reading in the log) the heading starts at north."""
    log = as_instance("log", log, ImuLog)
    declination_rad = as_angle("declination_rad", declination_rad)
    n_average = as_count("n_average", n_average, high=len(log))
    f = np.nanmean(log.accel[:n_average], axis=0)
    # without a magnetometer reading a "field" along body x: the body's heading is north
    m = np.array([1.0, 0.0, 0.0]) if log.mag is None else _first_field(log.mag, n_average * 5)
    if m is None:
        m = np.array([1.0, 0.0, 0.0])
    start = attitude_from_accel_mag(f[None], m[None])
    if not start.valid[0]:
        raise ValueError(f"log: expected the first {n_average} samples to give an attitude (gravity and a field not "
                         f"along it), got accel {f.round(3).tolist()}, mag {np.round(m, 3).tolist()}")
    turn = np.array([np.cos(declination_rad / 2), 0.0, 0.0, np.sin(declination_rad / 2)])
    q0 = quat_multiply(turn, start.q_nb[0])
    return np.concatenate([q0, as_vector("velocity", velocity, 3), as_vector("position", position, 3), np.zeros(6)])


def estimate_ins(log: ImuLog, gps: Samples, baro: Samples | None = None, params: InsParams = InsParams(), *,
                 decimate: int = 1, offline: bool = False, declination_rad: float = 0.0,
                 baro_offset_m: float | None = None, x0=None, compiled: bool = True) -> FilterRun:
    """Attitude, velocity, position and IMU biases from an IMU log, GPS and (optionally) a barometer.

    Parameters
    ----------
    log : ImuLog
        Gyro, accelerometer and (optionally) magnetometer, FRD; NaN rows are missing samples.
    gps : Samples
        ``[pn, pe, pd, vn, ve, vd]`` (NED m and m/s, as :func:`quadlib.data.load_px4_log` gives
        them); NaN rows are missing fixes. The first fix starts the filter.
    baro : Samples, optional
        Barometric altitude [m]; only its changes matter (see ``baro_offset_m``).
    params : InsParams
    decimate : int
        IMU samples averaged per filter step (:func:`imu_blocks`).
    offline : bool
        Smooth with the Rauch–Tung–Striebel backward pass in error-state form
        (:func:`quadlib.rts_smooth`): each estimate then uses the whole log. The forward pass then
        lets the heading correct the gyro bias too (the backward pass assumes optimal gains).
    declination_rad : float
        Magnetic declination [rad], east of true north.
    baro_offset_m : float, optional
        The barometer's reading at height 0 (down ``p_d = 0``); by default its mean over the first
        second, minus the first fix's height.
    x0 : (16,) array_like, optional
        Initial state; by default :func:`ins_initial_state` at the first fix.
    compiled : bool
        Run :class:`~quadlib.ModelEKF` on the compiled engine (:mod:`quadlib.engine`; the same
        kernels, equal to the readable filter to 1e-10, tested); False drives it with the readable
        loop of :func:`~quadlib.run_filter` (and :func:`~quadlib.rts_smooth`), as chapter 17
        builds it. ``run.engine`` says which ran.

    Returns
    -------
    FilterRun
        On the filter's grid (``imu_blocks``): ``x`` (N, 16), ``P`` over the 15 error states; the
        parts of ``x`` by name (``LAYOUT``): ``run.q``, ``run.v``, ``run.p``, ``run.gyro_bias``,
        ``run.accel_bias``.
    """
    log = as_instance("log", log, ImuLog)
    gps = as_instance("gps", gps, Samples)
    if gps.z.ndim != 2 or gps.z.shape[1] != 6:
        raise ValueError(f"gps: expected samples of [pn, pe, pd, vn, ve, vd], shape (K, 6), got {gps.z.shape}")
    if baro is not None:
        baro = as_instance("baro", baro, Samples)
    params = as_instance("params", params, InsParams)
    offline, compiled = as_bool("offline", offline), as_bool("compiled", compiled)
    if offline and params.heading_tilt_aware:
        raise ValueError("offline: expected the heading-only update for the smoother (its backward pass assumes an "
                         "optimal forward gain, which the tilt-aware consider update is not), got "
                         "InsParams(heading_tilt_aware=True)")
    declination_rad = as_angle("declination_rad", declination_rad)
    check_imu_units(log.t, log.gyro, log.accel, names=("log.t", "log.gyro", "log.accel"))
    check_gps_metres(gps.t, gps.z)
    if log.mag is not None:
        check_mag_frame(log.t, log.gyro, log.mag, ("log.mag", "log.gyro"))
    t, u = imu_blocks(log, decimate)
    gps = Samples(gps.t - params.gps_delay_s, gps.z)
    fixes = np.flatnonzero(~np.isnan(gps.z).any(axis=1) & (gps.t >= t[0]) & (gps.t <= t[-1]))
    if not fixes.size:
        raise ValueError(f"gps: expected at least one fix within the log's [{t[0]:.3f}, {t[-1]:.3f}] s, got none")
    start = int(np.searchsorted(t, gps.t[fixes[0]]))
    t, u = t[start:], u[start:]
    if x0 is None:
        x0 = ins_initial_state(log.slice(start * decimate), gps.z[fixes[0], :3], gps.z[fixes[0], 3:],
                               declination_rad)
    x0 = as_vector("x0", x0, 16)
    if not x0[Q_].any():
        raise ValueError(f"x0: expected a non-zero attitude quaternion in x0[:4], got {x0[Q_].tolist()}")
    P0 = params.initial_covariance(params.gps_pos_sigma_m, params.gps_vel_sigma_m_s)
    model = params.model(decimate)
    ekf = ModelEKF(model, x0, P0, float(np.median(np.diff(t))))

    gps_sensor = ins_gps_sensor(params.gps_pos_sigma_m, params.gps_vel_sigma_m_s, params.use_gps_height)
    gps = gps.between(t[0], t[-1])
    measurements = [Measurements(gps_sensor, gps.t, gps.z if params.use_gps_height else gps.z[:, [0, 1, 3, 4, 5]])]
    if baro is not None:
        baro = baro.between(t[0], t[-1])
        tb, zb = baro.t, baro.z
        if baro_offset_m is None:
            first = tb <= tb[0] + 1.0
            baro_offset_m = float(np.nanmean(zb[first])) + x0[9]
        offset = as_finite_number("baro_offset_m", baro_offset_m)
        measurements.append(Measurements(ins_baro_sensor(params.baro_sigma_m), tb, zb - offset))
    mag_log = log.slice(start * decimate, (start + t.size - 1) * decimate + 1)  # t[0] … t[-1]
    field_b = None if log.mag is None else _first_field(mag_log.mag, 100)
    if field_b is not None:
        field_n = quat_to_dcm(x0[Q_]) @ field_b
        good = plausible_mag(mag_log.mag, mag_log.accel, field_n, SensorChecks())
        mag = np.where(good[:, None], mag_log.mag, np.nan)
        # offline, the ordinary heading update: the backward pass assumes the forward gain is optimal
        heading = heading_sensor(params.heading_sigma_rad, corrects_bias=offline, dim_x=16,
                                 gyro_bias_errors=GYRO_BIAS_ERRORS, tilt_aware=params.heading_tilt_aware)
        measurements.append(Measurements(heading, mag_log.t, np.full(len(mag_log), declination_rad), context=mag))
    engine = "auto" if compiled else "readable"
    run = replace(run_filter(ekf, t, u, measurements, gate_probability=params.gate_probability, engine=engine),
                  layout=dict(LAYOUT))
    warn_unused(run.sensors)
    return rts_smooth(model, run, u, engine=engine) if offline else run
