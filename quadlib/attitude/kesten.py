"""The five attitude filters of Kesten (2010) §2.2.3, each a quadlib model run by :func:`run_filter`.

Every filter keeps ``q_nb`` (scalar first), predicts with the gyro (eq. 2.7, exact) and corrects
with the accelerometer and the magnetometer:

=======  ==============================  ==============================================  ===============
name     state (covariance)              correction                                      kind
=======  ==============================  ==============================================  ===============
TOVKF    orientation vector θ (3 × 3)    KF on the attitude from a and m (eq. 2.26)      additive EKF
TQKF     quaternion (4 × 4)              KF on the attitude quaternion (eq. 2.37)        additive EKF
TQF      quaternion (one variance)       geodesic step toward that attitude (2.44–2.48)  error-state EKF
QKF      quaternion (4 × 4)              EKF on a and m separately (eqs. 2.25, 2.54)     additive EKF
QF       quaternion (two variances)      two rotations toward a and m (2.55–2.64)        error-state EKF
=======  ==============================  ==============================================  ===============

Every filter first drops implausible accelerometer and magnetometer samples (a shock, free fall,
a magnet, a stuck sensor: :mod:`quadlib.attitude.checks`); the thesis trusts them all.

The "truncated" filters (T…) first compute an attitude from one accelerometer and one
magnetometer sample (:func:`quadlib.geometry.attitude_from_accel_mag`), so they correct only
when both are available; QKF and QF use each sensor on its own.

TQF and QF are Kalman filters in disguise: a scalar variance ``p`` per correction, a gain
``k = p/(p + r)`` and a turn ``q ← q ⊗ exp(k θ)`` are exactly a multiplicative EKF whose error
covariance stays ``p I₃`` (``G = I``, ``H = I``, ``R = r I``), so both run on :class:`ModelEKF`
with an error-state model — QF with one 3-D error block per sensor.

Differs from the source, each time for a reason given in the errata (chapter 13):

* process noise ``(σ_ω Δt)²`` per axis (E15), measurement variances ``σ²`` (E16);
* TQKF and QKF: the measured quaternion's sign is matched to the state's before subtracting,
  and the state is renormalised after every step (the thesis renormalises too);
* TOVKF: the measured orientation vector is taken in the representation nearest the state
  (θ or its 2π complement), so the filter survives rotations through 180°;
* QKF: process noise ``(σ_ω Δt/2)² I₄`` instead of eq. (2.51)'s ``G Q Gᵀ = (σ_ω Δt/2)² (I − q qᵀ)``
  (the extra variance along ``q`` is removed by renormalisation); measured vectors are scaled to
  the reference lengths before the update, as the thesis's implementation does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from quadlib.attitude.checks import SensorChecks, plausible_accel, plausible_mag
from quadlib.constants import GRAVITY_N, earth_field_ned
from quadlib.engine.kernel import Kernel, linear_kernels
from quadlib.filters import ModelEKF
from quadlib.geometry.quaternion import (
    quat_from_rotvec,
    quat_normalize,
    quat_to_rotvec,
)
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog, ImuNoise, untrusted_gyro_noise
from quadlib.kernels import attitude as attitude_maths
from quadlib.kernels import kesten as kesten_maths
from quadlib.model import Model, Sensor
from quadlib.replay import FilterRun, run_filter
from quadlib.samples import Measurements
from quadlib.validation import as_bool, as_positive, as_quaternions

__all__ = ["FILTERS", "AttitudeNoise", "AttitudeRun", "KestenFilter", "qf", "qkf", "run_attitude_filter", "tovkf",
           "tqf", "tqkf"]

@dataclass(frozen=True)
class AttitudeNoise(ImuNoise):
    """Kesten's sensors (§4.2–4.4: variances 2·10⁻⁵ rad²/s², 3.5·10⁻³ m²/s⁴, 2·10⁻⁶ G²) and field.

    Parameters (besides :class:`~quadlib.imu.ImuNoise`'s)
    ----------------------------------------------------
    field_gauss : float
        Strength of the Earth's field [G]; the magnetometer reports gauss.
    inclination_rad : float
        Its dip below the horizon [rad] (67°, northern Germany).
    thesis_process_noise : bool
        Use the thesis's gyro process noise ``Δt σ²_ω`` (eqs. 2.52, 2.57) instead of ``(σ_ω Δt)²`` (E15).
    """

    gyro_sigma_rad_s: float = float(np.sqrt(2e-5))
    accel_sigma_m_s2: float = float(np.sqrt(3.5e-3))
    mag_sigma: float = float(np.sqrt(2e-6))
    field_gauss: float = 0.5
    inclination_rad: float = float(np.radians(67.0))
    thesis_process_noise: bool = False

    FIELDS = ImuNoise.FIELDS | {"field_gauss": "positive", "inclination_rad": "finite", "thesis_process_noise": "bool"}

    @property
    def accel_n(self) -> np.ndarray:
        """The specific force at rest in NED, ``−g_n`` (up) [m/s²]."""
        return -GRAVITY_N

    @property
    def field_n(self) -> np.ndarray:
        """The Earth's field in NED [G]."""
        return earth_field_ned(self.field_gauss, self.inclination_rad)

    def gyro_step_variance(self, dt: float) -> float:
        """Variance of the attitude error one gyro step of ``dt`` [s] adds, per axis [rad²]:
        ``(σ_ω Δt)²``, or the thesis's ``Δt σ²_ω`` (``1/Δt`` = 250 times larger at 250 Hz)."""
        if self.thesis_process_noise:
            return dt * self.gyro_sigma_rad_s**2
        return (self.gyro_sigma_rad_s * dt) ** 2

    @property
    def r_accel(self) -> float:
        """Angular variance of one accelerometer direction, σ²_a/|a|² (eq. 2.33)."""
        return self.accel_sigma_m_s2**2 / float(self.accel_n @ self.accel_n)

    @property
    def r_mag(self) -> float:
        """Angular variance of one magnetometer direction, σ²_m/|m|² (eq. 2.34)."""
        return self.mag_sigma**2 / float(self.field_n @ self.field_n)


class KestenFilter(NamedTuple):
    """One of Kesten's filters as parts for :class:`ModelEKF` and :func:`run_filter`.

    ``samples(log)`` gives each sensor's ``(N, k)`` samples from an :class:`ImuLog` (NaN rows
    where it has none); ``state_from_q`` and ``q_from_state`` convert between ``q_nb`` and the state.
    ``noise`` is the noise the five factories built the filter from (for reading; the filter's
    model and sensors are what runs).
    """

    name: str
    model: Model
    P0: np.ndarray
    sensors: tuple[Sensor, ...]
    samples: Callable[[ImuLog], tuple[np.ndarray, ...]]
    state_from_q: Callable[[np.ndarray], np.ndarray] = quat_normalize
    q_from_state: Callable[[np.ndarray], np.ndarray] = quat_normalize
    noise: AttitudeNoise | None = None


# --- measured streams -------------------------------------------------------------------------

def _accel(log: ImuLog, checks: SensorChecks) -> np.ndarray:
    """The accelerometer, with implausible samples (shock, free fall) removed."""
    return np.where(plausible_accel(log.accel, checks)[:, None], log.accel, np.nan)


def _mag(log: ImuLog, noise: AttitudeNoise, checks: SensorChecks) -> np.ndarray:
    """The magnetometer, with implausible samples (norm or dip off the reference field) removed."""
    if log.mag is None:
        return np.full((len(log), 3), np.nan)
    return np.where(plausible_mag(log.mag, log.accel, noise.field_n, checks)[:, None], log.mag, np.nan)


def _scaled(v: np.ndarray, length: float) -> np.ndarray:
    return v * (length / np.linalg.norm(v, axis=1, keepdims=True))


def _measured_attitude(log: ImuLog, noise: AttitudeNoise, checks: SensorChecks) -> np.ndarray:
    """``(N, 4)`` attitude from each accelerometer + magnetometer pair (eqs. 2.2–2.5); NaN rows
    where either is missing or implausible, or the pair gives no attitude."""
    a, m = _accel(log, checks), _mag(log, noise, checks)
    both = ~(np.isnan(a).any(axis=1) | np.isnan(m).any(axis=1))
    out = np.full((len(log), 4), np.nan)
    if both.any():
        att = attitude_from_accel_mag(a[both], m[both])
        out[np.flatnonzero(both)[att.valid]] = att.q_nb[att.valid]
    return out


def _measured_rotvec(log: ImuLog, noise: AttitudeNoise, checks: SensorChecks) -> tuple[np.ndarray]:
    q = _measured_attitude(log, noise, checks)
    ok = ~np.isnan(q[:, 0])
    out = np.full((len(log), 3), np.nan)
    out[ok] = quat_to_rotvec(q[ok])
    return (out,)


# --- models and sensors ---------------------------------------------------------------------

def _checked(noise, sigma0_rad, checks) -> float:
    if not isinstance(noise, AttitudeNoise):
        raise TypeError(f"noise: expected an AttitudeNoise, got {type(noise).__name__}")
    if not isinstance(checks, SensorChecks):
        raise TypeError(f"checks: expected a SensorChecks, got {type(checks).__name__}")
    return as_positive("sigma0_rad", sigma0_rad)


_QUATERNION_STEP = Kernel("g", kesten_maths.quaternion_step)
_NORMALIZE = Kernel("normalize", attitude_maths.normalize_quaternion)


def _identity(n: int) -> Kernel:
    """``G = I_n``: the gyro step moves the error unchanged."""
    return Kernel("G", attitude_maths.identity_jacobian, [n])


def _gyro_noise(noise: AttitudeNoise, n: int, scale: float) -> Kernel:
    """``Q(Δt) = scale · v(Δt) I_n`` with ``v`` :meth:`AttitudeNoise.gyro_step_variance`."""
    return Kernel("Q", attitude_maths.gyro_noise, [noise.gyro_sigma_rad_s, float(noise.thesis_process_noise), scale, n,
                                             0.0, 0])


def _gyro_quaternion_model(noise: AttitudeNoise) -> Model:
    """``q ← q ⊗ exp(ω Δt)`` on the 4 components, process noise ``(σ_ω Δt/2)² I₄``."""
    return Model(state_names=("w", "x", "y", "z"), input_names=("p", "q", "r"),
                 g=_QUATERNION_STEP, G=_identity(4), Q=_gyro_noise(noise, 4, 0.25), normalize=_NORMALIZE,
                 input_noise=untrusted_gyro_noise(noise.gyro_range_rad_s, [0.25] * 4), name="gyro-driven quaternion")


def _rotation_error_model(noise: AttitudeNoise, blocks: int) -> Model:
    """``q`` with ``blocks`` rotation errors of 3 components each: ``q ⊞ δ = q ⊗ exp(δ₁) ⊗ exp(δ₂) …``
    (each update turns by one block only), ``⊟`` the whole turn in the first block."""
    names = tuple(f"dtheta{i}_{axis}" for i in range(1, blocks + 1) for axis in "xyz")
    n = 3 * blocks
    return Model(state_names=("w", "x", "y", "z"), input_names=("p", "q", "r"), error_names=names,
                 g=_QUATERNION_STEP, G=_identity(n), Q=_gyro_noise(noise, n, 1.0),
                 state_add=Kernel("state_add", kesten_maths.rotation_blocks_add, [blocks]),
                 residual_x=Kernel("residual_x", kesten_maths.rotation_blocks_difference, [blocks]),
                 normalize=_NORMALIZE, input_noise=untrusted_gyro_noise(noise.gyro_range_rad_s, [1.0] * n),
                 name="gyro-driven rotation error")


def tovkf(noise: AttitudeNoise = AttitudeNoise(), sigma0_rad: float = 1.0,
          checks: SensorChecks = SensorChecks()) -> KestenFilter:
    """Truncated orientation-vector Kalman filter: state θ, H = I₃, Φ = I₃ (eqs. 2.26–2.35)."""
    s0 = _checked(noise, sigma0_rad, checks)
    model = Model(state_names=("theta_x", "theta_y", "theta_z"), input_names=("p", "q", "r"),
                  g=Kernel("g", kesten_maths.orientation_vector_step), G=_identity(3),
                  Q=_gyro_noise(noise, 3, 1.0), input_noise=untrusted_gyro_noise(noise.gyro_range_rad_s, [1.0] * 3),
                  name="orientation vector")
    h, H = linear_kernels(np.eye(3, 3))
    # the residual: z, or the same attitude turned the other way round, whichever is nearer x
    sensor = Sensor(name="attitude", measurement_names=("theta_x", "theta_y", "theta_z"), h=h, H=H,
                    R=0.5 * (noise.r_accel + noise.r_mag) * np.eye(3),
                    residual=Kernel("residual", kesten_maths.nearest_orientation))
    return KestenFilter("TOVKF", model, s0**2 * np.eye(3), (sensor,), lambda log: _measured_rotvec(log, noise, checks),
                        state_from_q=quat_to_rotvec, q_from_state=quat_from_rotvec, noise=noise)


def tqkf(noise: AttitudeNoise = AttitudeNoise(), sigma0_rad: float = 1.0,
         checks: SensorChecks = SensorChecks()) -> KestenFilter:
    """Truncated quaternion Kalman filter: state q, H = I₄, Φ = I₄ (eqs. 2.36–2.43)."""
    s0 = _checked(noise, sigma0_rad, checks)
    h, H = linear_kernels(np.eye(4, 4))
    sensor = Sensor(name="attitude", measurement_names=("w", "x", "y", "z"), h=h, H=H,
                    R=0.25 * 0.5 * (noise.r_accel + noise.r_mag) * np.eye(4),
                    residual=Kernel("residual", kesten_maths.same_sign_quaternion))
    return KestenFilter("TQKF", _gyro_quaternion_model(noise), 0.25 * s0**2 * np.eye(4), (sensor,),
                        lambda log: (_measured_attitude(log, noise, checks),), noise=noise)


def tqf(noise: AttitudeNoise = AttitudeNoise(), sigma0_rad: float = 1.0,
        checks: SensorChecks = SensorChecks()) -> KestenFilter:
    """Truncated quaternion filter: a scalar-gain step along the geodesic toward the measured
    attitude (eqs. 2.44–2.48), as an error-state EKF with covariance ``p I₃``."""
    s0 = _checked(noise, sigma0_rad, checks)
    sensor = Sensor(name="attitude", measurement_names=("theta_x", "theta_y", "theta_z"),
                    h=Kernel("h", kesten_maths.quaternion_rotvec), H=linear_kernels(np.eye(3, 3))[1],
                    R=0.5 * (noise.r_accel + noise.r_mag) * np.eye(3),
                    residual=Kernel("residual", kesten_maths.rotvec_turn))
    return KestenFilter("TQF", _rotation_error_model(noise, 1), s0**2 * np.eye(3), (sensor,),
                        lambda log: _measured_rotvec(log, noise, checks), noise=noise)


def qkf(noise: AttitudeNoise = AttitudeNoise(), sigma0_rad: float = 1.0,
        checks: SensorChecks = SensorChecks()) -> KestenFilter:
    """Quaternion Kalman filter: the accelerometer and the magnetometer as nonlinear measurements
    of q (eqs. 2.25, 2.49–2.54), each updated on its own."""
    s0 = _checked(noise, sigma0_rad, checks)
    sensors = tuple(Sensor(name=name, measurement_names=("x", "y", "z"), h=Kernel("h", attitude_maths.body_vector, ref),
                           H=Kernel("H", attitude_maths.body_vector_H, [*ref, 4]), R=sigma**2 * np.eye(3))
                    for name, ref, sigma in (("accel", noise.accel_n, noise.accel_sigma_m_s2),
                                             ("mag", noise.field_n, noise.mag_sigma)))

    def samples(log):  # scaled to the reference lengths, as the thesis's implementation does
        return (_scaled(_accel(log, checks), float(np.linalg.norm(noise.accel_n))),
                _scaled(_mag(log, noise, checks), float(np.linalg.norm(noise.field_n))))

    return KestenFilter("QKF", _gyro_quaternion_model(noise), 0.25 * s0**2 * np.eye(4), sensors, samples, noise=noise)


def qf(noise: AttitudeNoise = AttitudeNoise(), sigma0_rad: float = 1.0,
       checks: SensorChecks = SensorChecks()) -> KestenFilter:
    """Quaternion filter: one variance per sensor, and rotations that bring the predicted gravity
    and field directions toward the measured ones (eqs. 2.55–2.64). The innovation is the turn
    between the two directions, so ``H`` selects that sensor's error block."""
    s0 = _checked(noise, sigma0_rad, checks)
    sensors = []
    for block, (name, ref, r) in enumerate((("accel", noise.accel_n, noise.r_accel),
                                            ("mag", noise.field_n, noise.r_mag))):
        sensors.append(Sensor(name=name, measurement_names=("x", "y", "z"),
                              h=Kernel("h", attitude_maths.body_vector, ref),
                              H=linear_kernels(np.eye(3, 6, 3 * block))[1], R=r * np.eye(3),
                              residual=Kernel("residual", kesten_maths.turn_between)))
    return KestenFilter("QF", _rotation_error_model(noise, 2), s0**2 * np.eye(6), tuple(sensors),
                        lambda log: (_accel(log, checks), _mag(log, noise, checks)), noise=noise)


FILTERS = {"TOVKF": tovkf, "TQKF": tqkf, "TQF": tqf, "QKF": qkf, "QF": qf}


class AttitudeRun(NamedTuple):
    """``q_nb`` (N, 4) estimates and the :class:`~quadlib.replay.FilterRun` behind them."""

    q_nb: np.ndarray
    run: FilterRun


def run_attitude_filter(filt: KestenFilter, log: ImuLog, q0=(1.0, 0.0, 0.0, 0.0), compiled: bool = True) -> AttitudeRun:
    """Run one of Kesten's filters over an IMU log with :func:`run_filter`.

    Parameters
    ----------
    filt : KestenFilter
        From :data:`FILTERS`, e.g. ``qkf(AttitudeNoise())``.
    log : ImuLog
        ``gyro[k]`` turns sample ``k`` into ``k + 1``; accelerometer and magnetometer rows of NaN
        are missing samples.
    q0 : (4,) array_like
        Initial attitude ``q_nb``.
    compiled : bool
        Run on the compiled engine (:mod:`quadlib.engine`; equal to the readable loop to 1e-10,
        tested) when the filter's model and sensors hold only compiled kernels, as the factories'
        do; a filter with a function in plain Python — a model changed with
        ``dataclasses.replace(model, Q=...)`` to one — runs on the readable loop, and
        ``run.engine`` says so. False always runs the readable loop.
    """
    if not isinstance(filt, KestenFilter):
        raise TypeError(f"filt: expected a KestenFilter (e.g. qkf(noise)), got {type(filt).__name__}")
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    compiled = as_bool("compiled", compiled)
    q0 = quat_normalize(as_quaternions("q0", q0))
    dt = float(log.t[1] - log.t[0]) if len(log) > 1 else 1.0
    ekf = ModelEKF(filt.model, filt.state_from_q(q0), filt.P0, dt)
    measurements = [Measurements(s, log.t, z) for s, z in zip(filt.sensors, filt.samples(log), strict=True)]
    run = run_filter(ekf, log.t, log.gyro, measurements, engine="auto" if compiled else "readable")
    return AttitudeRun(filt.q_from_state(run.x), run)
