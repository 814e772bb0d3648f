"""Fixed-wing attitude estimators on an IMU log, all driven by :func:`quadlib.run_filter`.

Three filters share the sensors of :mod:`quadlib.fixedwing.model`:

* :func:`salmony_ekf` — Salmony's EKF: additive over ``[q, b]``, Euler step, renormalised (§6–8);
* :func:`multiplicative_ekf` — the same sensors on the error-state model (exact gyro step,
  ``q ⊗ exp(δθ)``, a 6 × 6 covariance);
* :func:`error_state_ukf` — the error-state model in a UKF: sigma points in ``[δθ, δb]``.

:func:`fixedwing_measurements` turns a log into the samples each sensor sees, with Salmony's
failure handling (§8.3) as data: a sample with an airspeed goes to ``accel``, one without to
``accel (no airspeed)``, a NaN magnetometer row is a missing sample. :func:`estimate_fixedwing_attitude`
does all of it in one call with chapter 15's tuning.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from quadlib.attitude.bias_model import LAYOUT, as_attitude_state, attitude_bias_model
from quadlib.attitude.complementary import euler_rate_complementary
from quadlib.filters import ModelEKF, ModelUKF
from quadlib.fixedwing.model import (
    FixedWingNoise,
    fixedwing_accel_sensor,
    fixedwing_mag_sensor,
    fixedwing_model,
    lowpass2,
)
from quadlib.geometry.rotations import mag_heading
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog
from quadlib.model import Sensor
from quadlib.replay import FilterRun, run_filter
from quadlib.samples import Measurements
from quadlib.validation import as_angle, as_bool, as_count, as_finite_number, as_instance, as_positive, check_fields

__all__ = ["FixedWingParams", "complementary_attitude", "error_state_ukf", "estimate_fixedwing_attitude",
           "fixedwing_measurements", "initial_state", "multiplicative_ekf", "salmony_ekf"]


@dataclass(frozen=True)
class FixedWingParams:
    """Chapter 15's tuning of the fixed-wing filters.

    Parameters
    ----------
    quaternion_sigma0 : float
        Initial σ of each quaternion component in Salmony's EKF (dimensionless; 0.1 ≈ 0.2 rad).
    attitude_sigma0_rad : float
        Initial σ of the attitude error of the error-state filters [rad].
    bias_sigma0_rad_s : float
        Initial σ of each gyro bias [rad/s] (after the §8.1 initialisation).
    unmodelled_m_s2 : float
        Added to the accelerometer's σ when the airspeed is missing: the centripetal acceleration
        the model can no longer predict [m/s²] (3 m/s² ≈ a 20 m/s aircraft turning at 9°/s).
    n_still : int
        Samples averaged for the initial state (§8.1), from an unaccelerated, non-rotating stretch.
    gate_probability : float or None
        χ² gate on every accelerometer and magnetometer update (see :func:`quadlib.run_filter`). At
        0.999 it drops spikes and also the samples where eq. (13) is wrong — the speed changes,
        whose forward acceleration it would read as pitch.
    """

    quaternion_sigma0: float = 0.1
    attitude_sigma0_rad: float = 0.05
    bias_sigma0_rad_s: float = 0.02
    unmodelled_m_s2: float = 3.0
    n_still: int = 50
    gate_probability: float | None = 0.999

    def __post_init__(self):
        check_fields(self, {"quaternion_sigma0": "positive", "attitude_sigma0_rad": "positive",
                            "bias_sigma0_rad_s": "positive", "unmodelled_m_s2": "positive", "n_still": "count",
                            "gate_probability": "optional probability"})


def _process_noise(noise: FixedWingNoise) -> tuple[float, float, float | None]:
    # a filter needs some bias walk and some magnetometer noise even when the simulation has none
    return noise.gyro_sigma_rad_s, max(noise.gyro_bias_walk_rad_s_sqrt_s, 1e-6), noise.gyro_range_rad_s


def salmony_ekf(x0, noise: FixedWingNoise, dt: float, params: FixedWingParams = FixedWingParams()) -> ModelEKF:
    """Salmony's EKF (:func:`~quadlib.fixedwing.model.fixedwing_model`) at ``x0 = [q, b]``."""
    x0, noise, params = _filter_args(x0, noise, params)
    P0 = np.diag([params.quaternion_sigma0**2] * 4 + [params.bias_sigma0_rad_s**2] * 3)
    return ModelEKF(fixedwing_model(*_process_noise(noise)), x0, P0, dt)


def _filter_args(x0, noise, params):
    return (as_attitude_state("x0", x0), as_instance("noise", noise, FixedWingNoise),
            as_instance("params", params, FixedWingParams))


def _error_state_P0(params: FixedWingParams) -> np.ndarray:
    return np.diag([params.attitude_sigma0_rad**2] * 3 + [params.bias_sigma0_rad_s**2] * 3)


def multiplicative_ekf(x0, noise: FixedWingNoise, dt: float, params: FixedWingParams = FixedWingParams()) -> ModelEKF:
    """The error-state model (:func:`~quadlib.attitude.attitude_bias_model`) in an EKF."""
    x0, noise, params = _filter_args(x0, noise, params)
    return ModelEKF(attitude_bias_model(*_process_noise(noise)), x0, _error_state_P0(params), dt)


def error_state_ukf(x0, noise: FixedWingNoise, dt: float, params: FixedWingParams = FixedWingParams()) -> ModelUKF:
    """The error-state model in a UKF (default sigma points, α = 0.5)."""
    x0, noise, params = _filter_args(x0, noise, params)
    return ModelUKF(attitude_bias_model(*_process_noise(noise)), x0, _error_state_P0(params), dt)


def initial_state(log: ImuLog, n_still: int) -> np.ndarray:
    """§8.1: the gyro bias as the mean of the first ``n_still`` gyro samples, the attitude from their
    mean accelerometer and magnetometer vectors. The samples must come from an unaccelerated,
    non-rotating stretch: at rest, or in steady straight and level flight."""
    log = as_instance("log", log, ImuLog)
    n_still = as_count("n_still", n_still)
    if log.mag is None:
        raise ValueError("log.mag: expected magnetometer samples for the initial heading, got None")
    accel, mag, gyro = log.accel[:n_still], log.mag[:n_still], log.gyro[:n_still]
    present = [~np.isnan(v).any(axis=1) for v in (accel, mag, gyro)]  # dropouts are averaged over
    if not all(p.any() for p in present):
        raise ValueError(f"log: expected gyro, accelerometer and magnetometer samples among the first {n_still}, got "
                         f"{present[2].sum()}, {present[0].sum()} and {present[1].sum()}")
    att = attitude_from_accel_mag(accel[present[0]].mean(axis=0)[None], mag[present[1]].mean(axis=0)[None])
    if not att.valid[0]:
        raise ValueError(f"log: the first {n_still} samples give no attitude (free fall, or field parallel to gravity)")
    return np.concatenate([att.q_nb[0], gyro[present[2]].mean(axis=0)])


def fixedwing_measurements(log: ImuLog, accel_sigma_m_s2: float, mag_sensor: Sensor,
                           unmodelled_m_s2: float = 3.0, prefilter_hz: float | None = None) -> list[Measurements]:
    """The samples of the two accelerometer models and the magnetometer, for :func:`run_filter`.

    Each accelerometer sample carries its gyro rates (and airspeed) as context. Where the airspeed
    is NaN the sample goes to the no-airspeed model instead (§8.3). ``prefilter_hz`` low-passes the
    accelerometer and magnetometer first (eqs. 7–8).
    """
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    if log.airspeed is None or log.mag is None:
        raise ValueError("log: expected magnetometer and airspeed samples (NaN where missing), got None")
    mag_sensor = as_instance("mag_sensor", mag_sensor, Sensor)
    accel_sigma_m_s2 = as_positive("accel_sigma_m_s2", accel_sigma_m_s2)
    unmodelled_m_s2 = as_positive("unmodelled_m_s2", unmodelled_m_s2)
    if prefilter_hz is not None:
        prefilter_hz = as_positive("prefilter_hz", prefilter_hz)
    accel, mag = log.accel, log.mag
    if prefilter_hz is not None:
        dt = float(log.t[1] - log.t[0])
        accel, mag = lowpass2(accel, prefilter_hz, dt), lowpass2(mag, prefilter_hz, dt)
    no_airspeed = np.isnan(log.airspeed)
    with_va = np.where(no_airspeed[:, None], np.nan, accel)
    without_va = np.where(no_airspeed[:, None], accel, np.nan)
    return [Measurements(fixedwing_accel_sensor(accel_sigma_m_s2), log.t, with_va,
                         context=np.column_stack([log.gyro, log.airspeed])),
            Measurements(fixedwing_accel_sensor(accel_sigma_m_s2, unmodelled_m_s2), log.t, without_va,
                         context=log.gyro),
            Measurements(mag_sensor, log.t, mag)]


def estimate_fixedwing_attitude(log: ImuLog, noise: FixedWingNoise = FixedWingNoise(), filter_factory=salmony_ekf,
                                inclination_rad: float | None = None, prefilter_hz: float | None = None,
                                params: FixedWingParams = FixedWingParams(), compiled: bool = True) -> FilterRun:
    """Attitude and gyro bias of a fixed-wing aircraft from its IMU, magnetometer and airspeed, in one call.

    Parameters
    ----------
    log : ImuLog
        With ``mag`` (unit vector or any unit; it is compared as a direction) and ``airspeed``; NaN
        rows are missing samples. The first ``params.n_still`` samples initialise the filter.
    noise : FixedWingNoise
        The sensors' noise and the field's declination and inclination.
    filter_factory : callable
        :func:`salmony_ekf` (default), :func:`multiplicative_ekf` or :func:`error_state_ukf`.
    inclination_rad : float, optional
        The dip the magnetometer model assumes (default ``noise.inclination_rad``; 0 is the
        document's horizontal field).
    prefilter_hz : float, optional
        Cut-off of Salmony's second-order prefilter; none by default.
    params : FixedWingParams
    compiled : bool
        Run the same steps on the compiled engine (:mod:`quadlib.engine`; equal to the readable
        loop to 1e-10, tested; ``run.engine`` says which ran). False runs the readable filter,
        :class:`~quadlib.ModelEKF` or :class:`~quadlib.ModelUKF` driven by :func:`~quadlib.run_filter`.

    Returns
    -------
    FilterRun
        ``x`` is ``[q_nb, b]`` (N, 7) for every filter: ``run.q`` and ``run.gyro_bias``.
    """
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    if not isinstance(noise, FixedWingNoise):
        raise TypeError(f"noise: expected a FixedWingNoise, got {type(noise).__name__}")
    if not callable(filter_factory):
        raise TypeError(f"filter_factory: expected a callable such as salmony_ekf, got {filter_factory!r}")
    params = as_instance("params", params, FixedWingParams)
    compiled = as_bool("compiled", compiled)
    incl = noise.inclination_rad if inclination_rad is None else as_finite_number("inclination_rad", inclination_rad)
    dt = float(log.t[1] - log.t[0])
    filt = filter_factory(initial_state(log, params.n_still), noise, dt, params)
    mag = fixedwing_mag_sensor(noise.declination_rad, max(noise.mag_sigma, 1e-6), incl)
    measurements = fixedwing_measurements(log, noise.accel_sigma_m_s2, mag, params.unmodelled_m_s2, prefilter_hz)
    run = run_filter(filt, log.t, log.gyro, measurements, gate_probability=params.gate_probability,
                     engine="auto" if compiled else "readable")
    return replace(run, layout=dict(LAYOUT))


def complementary_attitude(log: ImuLog, declination_rad: float, tau_s: float = 1.0) -> np.ndarray:
    """Chapter 10's Euler-rate complementary filter for roll and pitch (time constant ``tau_s`` [s])
    and the tilt-compensated magnetometer heading for yaw: no bias estimate, no airspeed.
    Returns roll, pitch, yaw ``(N, 3)`` [rad]. Over a magnetometer gap the last heading holds
    (before the first sample, the first one)."""
    log = as_instance("log", log, ImuLog)
    if log.mag is None:
        raise ValueError("log.mag: expected magnetometer samples (NaN where missing), got None")
    declination_rad = as_angle("declination_rad", declination_rad)
    dt = float(log.t[1] - log.t[0])
    roll_pitch = euler_rate_complementary(dt, log.gyro, log.accel, as_positive("tau_s", tau_s))
    present = ~np.isnan(log.mag).any(axis=1)
    if not present.any():
        raise ValueError("log.mag: expected at least one magnetometer sample, got none")
    k = np.flatnonzero(present)
    heading = mag_heading(log.mag[k], roll_pitch[k, 0], roll_pitch[k, 1], declination_rad)
    last = np.maximum.accumulate(np.where(present, np.arange(len(log)), -1))  # the latest sample so far
    yaw = heading[np.searchsorted(k, np.where(last >= 0, last, k[0]))]
    return np.column_stack([roll_pitch, yaw])
