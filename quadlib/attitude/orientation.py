"""Orientation of a strapdown IMU: a multiplicative EKF over attitude and gyro bias.

The gyro drives the prediction (:func:`~quadlib.attitude.bias_model.attitude_bias_model`); two
updates correct it, each only where its sensor can be trusted:

* **gravity** — the accelerometer, averaged in a non-rotating frame, as the specific force at
  rest, ``h(x) = R(q)ᵀ(−g_n)``, skipped when its norm is off g₀ (:mod:`quadlib.attitude.checks`)
  and gated on its NIS, so shocks, free fall and a lasting acceleration (a banked turn) do not tilt
  the estimate; after 30 s of refusals the tilt is reset to it (``gravity_reset_s``);
* **heading** — the magnetometer corrects the heading only: the measured field, turned into the
  earth frame with the current attitude, should point to magnetic north; its horizontal angle is
  the innovation. The field's dip never touches roll and pitch (they come from gravity), and
  samples whose norm, dip or repetition say "disturbed" are skipped.

The gyro bias is learnt from gravity and, at rest, from the gyro itself (a zero-rate update); the
magnetometer never touches it (see :func:`heading_sensor`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from quadlib.attitude.bias_model import LAYOUT, attitude_bias_model
from quadlib.attitude.checks import SensorChecks, plausible_accel, undisturbed_field
from quadlib.attitude.lowpass import inertial_lowpass, rest_mask
from quadlib.attitude.start import initial_attitude
from quadlib.attitude.tilt import refined_tilt
from quadlib.filters import ModelEKF
from quadlib.geometry.quaternion import quat_to_dcm
from quadlib.imu import ImuLog, as_imu_stream, gyro_with_gaps, rates_to_interval_start
from quadlib.model import Model, Sensor
from quadlib.plausibility import check_imu_units, check_mag_frame, warn_unused
from quadlib.replay import FilterRun, rts_smooth, run_filter
from quadlib.samples import Measurements
from quadlib.sensors import gravity_sensor, heading_sensor, zero_rate_sensor
from quadlib.validation import as_angle, as_bool, as_times, check_fields

__all__ = ["OrientationParams", "estimate_orientation", "gravity_sensor", "heading_sensor", "orientation_run",
           "zero_rate_sensor"]


@dataclass(frozen=True)
class OrientationParams:
    """Parameters of :func:`estimate_orientation`, each with its unit.

    Parameters
    ----------
    gyro_sigma_rad_s : float
        Gyro white noise per sample [rad/s].
    gyro_bias_walk_rad_s_sqrt_s : float
        Random walk of the gyro bias [rad/s/√s]. A small one keeps the bias where the rests put it
        while the board is carried: the averaged gravity's errors then last seconds, and with a
        faster walk the bias learns them (on BROAD's trial 10, 0.117 -> 0.163 °/s about z during the
        motion with 1e-4, where VQF's holds within 0.005).
    gravity_sigma_m_s2 : float
        Accelerometer σ for the gravity update [m/s²]: sensor noise plus the motion's own
        accelerations, which the update treats as noise. With the low-passed accelerometer
        (``accel_tau_s``) it sets how fast gravity pulls the tilt. It, ``accel_tau_s``,
        ``tilt_aware_heading``, ``gyro_bias_walk_rad_s_sqrt_s`` and ``checks.mag_norm_tolerance``
        were chosen together on the ten BROAD trials the project ships, by leave-one-trial-out: on
        a grid of σ 0.3, 0.5 and 1.0 m/s², τ 1.5 and 3 s, both heading updates, walks 1e-4 and
        3e-5, field tolerances 20, 10 and 5 % and the tilt refined or not (``tilt_refinement_deg``),
        the setting with the lowest mean total error on nine trials was scored on the tenth, and
        every fold chose these defaults
        (``benchmarks/broad_loo.py``, which prints the held-out table).
    heading_sigma_rad : float
        σ of one magnetometer heading [rad].
    tilt_aware_heading : bool
        The heading update that accounts for the tilt's share of the heading's error
        (:func:`heading_sensor` with ``tilt_aware``); False: the heading-only update. Offline, the
        heading-only ordinary update is used either way (the smoother needs the optimal gain).
    heading_reset_s : float or None
        After the gate has refused the heading for this long [s], the heading is reset to the
        magnetometer's, but only if the readings it refused agree with one another
        (``Sensor.reset_needs_agreement``): then the estimate is what is off. Readings that scatter
        more than their noise, as a magnet turning with the sensor makes them, stay refused. None:
        a refused heading is never reset. With gravity gated (``gravity_reset_s``) no reset happens
        on chapter 15's fixed-wing flight, and one on the ten BROAD trials (trial 34 at 70 s: 3.28°
        total error, 3.20° without the reset). Ungated, the flight's turns tilt the estimate, and
        the bias learnt from that turns the heading away until the gate refuses every heading: over
        ten noise draws at 25, 50 and 100 Hz the mean total error is 21.8°, 27.2° and 40.2° without
        the reset, 18.0°, 20.4° and 27.3° with it.
    initial_bias_sigma_rad_s : float
        σ of the gyro bias at the start [rad/s] (the bias starts at zero).
    gate_probability : float or None
        χ² gate on the heading, zero-rate and gravity updates (the low-passed gravity only with
        ``gravity_reset_s``).
    gravity_reset_s : float or None
        Gravity is gated, the low-passed gravity too, and once the gate has refused it for this long
        [s] the tilt is reset to it (``Sensor.reset_after_s``). A sustained acceleration — a banked
        turn, whose specific force stays along the body's z — survives the low-pass and disagrees
        with the tilt the gyro carried: the gate refuses it, and the gyro alone carries the tilt
        through it. Ungated, the turn pulls the estimate level, the gyro bias learns the difference
        and turns the heading away. On chapter 15's fixed-wing flight without airspeed (ten noise
        draws each at 25, 50 and 100 Hz; ``benchmarks/orientation_rates.py``) the mean total error
        is 3.1°, 3.5° and 4.4° with 30 s, 18.0°, 20.4° and 27.3° with None, and VQF's 18.6°, 18.5°
        and 18.6°; on the ten BROAD trials, 1.61° with 30 s and 1.60° with None. 30 s was chosen
        with that flight in view: it outlasts its longest turn (18 s). The reset is what makes the
        gate safe: an average over seconds cannot jump, so once an estimate has drifted from it a
        gate alone would refuse it for good. None: the low-passed gravity is never gated (the raw
        accelerometer's still is, with no reset).
    tilt_refinement_deg : float or None
        The estimate's tilt is moved toward the one the accelerometer gives averaged by VQF's
        second-order low-pass (``accel_tau_s``, de-biased with the filter's bias; two-sided offline):
        nearly all the way while the two agree, not at all once they part by this many degrees
        (:func:`~quadlib.attitude.tilt.refined_tilt`; at most a quarter of it). The filter itself
        is unchanged: ``run.x``'s quaternion is the refined one, but ``run.P``, the innovations and
        every update refer to the filter's own tilt, so a consistency test (NEES) or a restart from
        ``run.x`` should use ``tilt_refinement_deg=None``. Why: the Kalman update smooths the
        averaged gravity again, and its tilt lags the average (offline, where the smoother's tilt
        does not lag, the gain is smaller). In the average's first τ seconds, a running mean, a
        start in motion is pulled by up to a quarter of the width. On the ten BROAD trials the mean inclination error
        falls from 0.71° to 0.65° online (VQF's 0.67°; ``benchmarks/broad_loo.py``, where every fold
        keeps it) and from 0.59° to 0.57° offline, the heading's unchanged; on chapter 15's flight
        the mean total error is 3.1°, 3.5° and 4.4° at 25, 50 and 100 Hz, against 3.2°, 3.6° and
        4.5° without it. 4° was chosen from two facts, not swept: where nothing lasting
        accelerates the sensor the two part by under 1° (BROAD's 99th percentile), and in a banked
        turn by the bank angle. None: the filter's tilt.
    checks : SensorChecks
        When an accelerometer or magnetometer sample is implausible and skipped. The field's
        strength must stay within 5 % of the reference's (:class:`SensorChecks`' own default is
        20 %): a field 8 % stronger, as where BROAD's trials 10 and 15 carry the board, also points
        a few degrees elsewhere, and the gyro, with its bias held, is the better heading there
        (``mag_new_field_s`` takes a new field that holds steady).
    gyro_range_rad_s : float or None
        The gyro's full scale [rad/s]; a sample at it adds attitude uncertainty
        (:func:`~quadlib.imu.saturated_step_variance`). None: never saturates.
    gyro_gap_accel_rad_s2 : float or None
        How fast the turn rate may change [rad/s²] while the gyro is missing (NaN rows): the last
        real sample stands in for the missing ones, ``τ`` seconds after it with an attitude variance
        of ``(α τ Δt)²`` per step (:func:`~quadlib.imu.untrusted_gyro_noise`), and the accelerometer's
        low-pass starts afresh once the gap may have turned its frame by more than a degree
        (``α τ²/2``). 100 rad/s², a hand-held turn reaching 1000 °/s in a sixth of a second: one
        missing sample costs nothing, half a second leaves the attitude unknown and the filter
        finds it again from gravity and the field. None: a gap is bridged at the last rate, trusted.
    accel_tau_s : float or None
        Time constant [s] of the accelerometer's low-pass in the non-rotating frame
        (:func:`inertial_lowpass`); None: the raw samples. VQF's default, 3 s (see
        ``gravity_sigma_m_s2``). The low-pass needs the gyro bias, so it takes a second filter
        pass: None runs one pass and no low-pass, at 0.45 times the cost
        (``benchmarks/orientation_cost.py``), but its mean total error on the ten BROAD trials is
        6.5° against the defaults' 1.6° (``benchmarks/orientation_ablation.py``, which switches
        off each setting in turn).
    mag_settle_s : float or None
        After a field sample fails its checks, the magnetometer is trusted again only once its
        samples have passed them for this long [s] (VQF's 0.5 s, ``magMinUndisturbedTime``): a
        magnet moving away passes through plausible readings on its way. None: trusted at once.
    mag_check_tau_s : float
        The field's norm and dip are checked on a first-order low-pass of this time constant [s]
        (VQF's 0.05 s), not reading by reading: a noisy magnetometer's single readings stray past
        the tolerances (:func:`~quadlib.attitude.checks.undisturbed_field`).
    mag_reference_tau_s : float or None
        While the field is trusted, the norm and dip it is checked against follow it with this time
        constant [s] (VQF's 20 s, ``magRefTau``): the Earth's field differs from room to room. None:
        the first reading's field throughout. Both online only: offline, where the heading update
        also corrects the gyro bias (the smoother needs its optimal gain), a disturbance that passed
        would reach the bias, so each reading is judged alone against the start's field, which
        refuses more (on the ten BROAD trials, with the filter's own tilt, the smoother's mean total
        error is 1.19° so, 2.09° with the average and the learnt reference).
    mag_new_field_s : float or None
        A refused field that holds steady for this long [s] while the sensor turns faster than
        20 °/s becomes the new reference (VQF's 20 s, ``magNewTime``): a reference taken from a
        disturbed or accelerated first reading is not kept for good. None: never replaced.
    mag_first_field_s : float or None
        The first reading's field, the reference the checks start from, stays on trial until it has
        been trusted for this long [s] (VQF's ``magNewFirstTime``, 5 s): until then a refused field
        that holds steady for this long, at rest or turning, replaces it, so a magnet beside the
        start is not kept as the Earth's field (:func:`~quadlib.attitude.checks.undisturbed_field`).
        On BROAD's ten trials with the first 3 s of readings 1.5 times too strong, the mean total
        error is 1.61° against 2.85° with None; with the first reading 10 s into the motion, 7.69°
        against 8.01°; as logged, or with VQF's disturbed readings left out, the estimates are
        unchanged (``benchmarks/magnetometer_schedules.py``). None: the first reading's field is kept.
    rest_gyro_rad_s, rest_accel_m_s2 : float
        At rest when neither the gyro nor the accelerometer strays further than these from its own
        low-pass (:func:`rest_mask`, VQF's thresholds: 2 °/s, 0.5 m/s²) ...
    rest_min_s : float or None
        ... for at least this long [s]; at rest the gyro measures its bias (a zero-rate update,
        :func:`zero_rate_sensor`). None: no rest detection.
    """

    gyro_sigma_rad_s: float = 0.005
    gyro_bias_walk_rad_s_sqrt_s: float = 3e-5
    gravity_sigma_m_s2: float = 0.3
    heading_sigma_rad: float = 0.1
    tilt_aware_heading: bool = True
    heading_reset_s: float | None = 1.0
    initial_bias_sigma_rad_s: float = 0.01
    gate_probability: float | None = 0.999
    gravity_reset_s: float | None = 30.0
    tilt_refinement_deg: float | None = 4.0
    checks: SensorChecks = field(default_factory=lambda: SensorChecks(mag_norm_tolerance=0.05))
    gyro_range_rad_s: float | None = None
    gyro_gap_accel_rad_s2: float | None = 100.0
    accel_tau_s: float | None = 3.0
    mag_settle_s: float | None = 0.5
    mag_check_tau_s: float = 0.05
    mag_reference_tau_s: float | None = 20.0
    mag_new_field_s: float | None = 20.0
    mag_first_field_s: float | None = 5.0
    rest_gyro_rad_s: float = float(np.radians(2.0))
    rest_accel_m_s2: float = 0.5
    rest_min_s: float | None = 1.5

    def __post_init__(self):
        check_fields(self, {"gyro_sigma_rad_s": "positive", "gyro_bias_walk_rad_s_sqrt_s": "positive",
                            "gravity_sigma_m_s2": "positive", "heading_sigma_rad": "positive",
                            "tilt_aware_heading": "bool", "heading_reset_s": "optional positive",
                            "initial_bias_sigma_rad_s": "positive",
                            "gate_probability": "optional probability", "gravity_reset_s": "optional positive",
                            "tilt_refinement_deg": "optional positive",
                            "gyro_range_rad_s": "optional positive",
                            "gyro_gap_accel_rad_s2": "optional positive", "accel_tau_s": "optional positive",
                            "mag_settle_s": "optional positive", "mag_check_tau_s": "positive",
                            "mag_reference_tau_s": "optional positive", "mag_new_field_s": "optional positive",
                            "mag_first_field_s": "optional positive",
                            "rest_gyro_rad_s": "positive",
                            "rest_accel_m_s2": "positive", "rest_min_s": "optional positive"})
        if not isinstance(self.checks, SensorChecks):
            raise TypeError(f"OrientationParams.checks: expected a SensorChecks, got {self.checks!r}")


def estimate_orientation(t, gyr=None, acc=None, mag=None, params: OrientationParams | None = None, *,
                         offline: bool = False, declination_rad: float = 0.0) -> FilterRun:
    """The orientation of an IMU at every sample, and its gyro bias: the one-call API.

    ``estimate_orientation(...).q`` is ``q_nb`` (N, 4), scalar first, sensor → NED;
    ``.gyro_bias`` (N, 3) [rad/s]; the rest of the run is :func:`orientation_run`'s.

    Parameters
    ----------
    t : (N,) array_like or ImuLog
        Sample times [s]; or an :class:`~quadlib.imu.ImuLog`, and then no ``gyr``, ``acc``, ``mag``
        (its ``gyro[k]`` is the rate over ``[t[k], t[k+1])``, as the loaders give it).
    gyr, acc : (N, 3) array_like
        Gyro [rad/s] and accelerometer [m/s²] in the sensor frame; NaN rows are missing samples.
        ``gyr[k]`` is the rate over the interval that *ends* at ``t[k]``, ``(t[k−1], t[k]]``, as
        most IMUs, VQF and BROAD have it: each row is moved one earlier for the filter (the first
        row's interval lies before the log and is not used). ``acc`` is the specific force, what an
        accelerometer reads: ``(0, 0, −9.81)`` lying level in FRD. Gravity itself, its negative,
        reads like a sensor mounted upside down and cannot be told from one by the IMU alone: it is
        not caught (the estimate is then 180° off).
    mag : (N, 3) array_like, optional
        Magnetometer (any unit: only its direction is used); without it the heading is the gyro's.
        Any schedule: NaN rows are readings not taken. A first reading after the first sample is
        turned back through the gyro to give the start's heading, and it is the reference the
        checks judge later readings against (replaced by a field that holds steady while the
        sensor turns, ``OrientationParams.mag_new_field_s``).
    params : OrientationParams, optional
        The tuned defaults when None.
    offline : bool
        Smooth the forward estimate with a backward pass (:func:`~quadlib.replay.rts_smooth`):
        each sample's attitude then also uses what came after it. For post-flight analysis.
    declination_rad : float
        Where magnetic north is, east of true north [rad].

    Returns
    -------
    FilterRun
        ``x`` is ``[q_nb, b]`` per sample (``run.q``, ``run.gyro_bias``), smoothed when ``offline``.
    """
    if isinstance(t, ImuLog):
        if gyr is not None or acc is not None or mag is not None:
            raise TypeError("gyr, acc, mag: expected none of them with an ImuLog as t, got "
                            f"{[k for k, v in (('gyr', gyr), ('acc', acc), ('mag', mag)) if v is not None]}")
        log = t
        names = ("t.t", "t.gyro", "t.accel", "t.mag")
    else:
        t = as_times("t", t)
        n = t.size
        gyr = as_imu_stream("gyr", gyr, n)
        log = ImuLog(t, rates_to_interval_start(gyr), as_imu_stream("acc", acc, n),
                     as_imu_stream("mag", mag, n, required=False))
        names = ("t", "gyr", "acc", "mag")
    check_imu_units(log.t, log.gyro, log.accel, names[:3])
    first = int(np.argmax(np.isfinite(log.gyro).all(axis=1)))
    if first:  # no rate before the first reading: hold the first one back to the start
        log = replace(log, gyro=np.vstack([np.repeat(log.gyro[first:first + 1], first, axis=0), log.gyro[first:]]))
    if log.mag is not None:
        check_mag_frame(log.t, log.gyro, log.mag, (names[3], names[1]))
    run = orientation_run(log, OrientationParams() if params is None else params, offline=offline,
                          declination_rad=declination_rad)
    if log.mag is not None and "heading" not in run.sensors:
        warnings.warn(f"{names[3]}: expected at least one reading that gives a heading, got none; the heading is "
                      "the gyro's alone, from body x (or y) pointing north at the start", stacklevel=2)
    streams = {} if log.mag is None else {"heading": (names[3], np.isfinite(log.mag).all(axis=1))}
    warn_unused(run.sensors, streams)
    return run


def orientation_run(log: ImuLog, params: OrientationParams = OrientationParams(), *, offline: bool = False,
                    declination_rad: float = 0.0, compiled: bool = True) -> FilterRun:
    """The filter run behind :func:`estimate_orientation`: ``run.x`` is ``[q_nb, b]`` per sample
    (attitude and gyro bias [rad/s]: ``run.q``, ``run.gyro_bias``), ``run.P`` the covariance of
    ``[δθ, δb]``, ``run.sensors`` what each update did (the forward pass's, also when ``offline``).

    Starts from the first accelerometer and magnetometer pair that gives an attitude, bias zero.
    The filter is :class:`~quadlib.ModelEKF` driven by :func:`~quadlib.replay.run_filter` (and
    :func:`~quadlib.replay.rts_smooth` offline), whose model and sensors are compiled kernels: by
    default both run on the compiled engine (:mod:`quadlib.engine`; equal to the readable loop to
    1e-10, tested); ``compiled=False`` runs the readable loops.
    """
    if not isinstance(log, ImuLog):
        raise TypeError(f"log: expected an ImuLog, got {type(log).__name__}")
    if not isinstance(params, OrientationParams):
        raise TypeError(f"params: expected an OrientationParams, got {type(params).__name__}")
    offline, compiled = as_bool("offline", offline), as_bool("compiled", compiled)
    declination_rad = as_angle("declination_rad", declination_rad)
    engine = "auto" if compiled else "readable"
    start = initial_attitude(log, declination_rad)
    rest = None if params.rest_min_s is None else rest_mask(log, params.rest_gyro_rad_s, params.rest_accel_m_s2,
                                                              params.rest_min_s)
    if params.accel_tau_s is None:
        run, model = _orientation_pass(log, params, declination_rad, start, rest, log.accel, offline, engine)
    else:
        tau, alpha = params.accel_tau_s, params.gyro_gap_accel_rad_s2
        first, _ = _orientation_pass(log, params, declination_rad, start, rest,
                                     inertial_lowpass(log, tau, gap_accel_rad_s2=alpha), offline, engine)
        gravity = inertial_lowpass(log, tau, first.x[:, 4:], two_sided=offline, gap_accel_rad_s2=alpha)
        run, model = _orientation_pass(log, params, declination_rad, start, rest, gravity, offline, engine,
                                       first.x[:, :4])
    if offline:
        run = rts_smooth(model, run, _gyro_input(log, params), engine=engine)
    if params.accel_tau_s is not None and params.tilt_refinement_deg is not None:  # the tilt read from VQF's average
        average = inertial_lowpass(log, params.accel_tau_s, run.x[:, 4:], two_sided=offline,
                                   gap_accel_rad_s2=params.gyro_gap_accel_rad_s2, second_order=True)
        q = refined_tilt(run.x[:, :4], average, np.radians(params.tilt_refinement_deg))
        run = replace(run, x=np.column_stack([q, run.x[:, 4:]]))
    return replace(run, layout=dict(LAYOUT))


def _gyro_input(log: ImuLog, params: OrientationParams) -> np.ndarray:
    """The filter's input: the gyro, with the seconds each held row stands in (:func:`~quadlib.imu.gyro_with_gaps`)
    when the model prices gaps."""
    return log.gyro if params.gyro_gap_accel_rad_s2 is None else gyro_with_gaps(log.t, log.gyro)


@lru_cache(maxsize=16)
def _filter_parts(params: OrientationParams, offline: bool) -> tuple[Model, Sensor, Sensor, Sensor]:
    """The model and the gravity, heading and zero-rate sensors of a pass with ``params``: built (and
    checked) once a process for each setting, as the model and sensors are immutable."""
    model = attitude_bias_model(params.gyro_sigma_rad_s, params.gyro_bias_walk_rad_s_sqrt_s, params.gyro_range_rad_s,
                                params.gyro_gap_accel_rad_s2)
    gated = params.accel_tau_s is None or params.gravity_reset_s is not None
    tilt = gravity_sensor(params.gravity_sigma_m_s2, gated=gated)
    if params.gravity_reset_s is not None:  # refused gravity: a sustained acceleration, until it lasts this long
        tilt = replace(tilt, reset_after_s=params.gravity_reset_s)
    # offline, the ordinary heading update: the backward pass assumes the forward gain is optimal
    heading = heading_sensor(params.heading_sigma_rad, corrects_bias=offline,
                             tilt_aware=params.tilt_aware_heading and not offline)
    if params.heading_reset_s is not None:
        heading = replace(heading, reset_after_s=params.heading_reset_s, reset_needs_agreement=True)
    return model, tilt, heading, zero_rate_sensor(params.gyro_sigma_rad_s)


def _orientation_pass(log: ImuLog, params: OrientationParams, declination_rad: float, start, rest, gravity,
                      offline: bool, engine: str, attitude=None):
    """One filter pass from ``start`` (:func:`~quadlib.attitude.start.initial_attitude`'s), with the
    zero-rate update where ``rest`` (None: never) and ``gravity`` as the accelerometer; ``attitude`` (a
    first pass's ``q_nb``) is the down direction the field's dip is checked against (else the
    accelerometer's)."""
    checks = params.checks
    good_a = plausible_accel(gravity, checks)
    accel = np.where(good_a[:, None], gravity, np.nan)
    q0, has_mag = start
    if has_mag:
        down = -accel / np.linalg.norm(accel, axis=1, keepdims=True) if attitude is None else \
            quat_to_dcm(attitude)[:, 2, :]  # NED's down in the body frame: the third row of R(q)
        # offline, each reading alone against the start's field: the heading update also corrects the bias there
        good_m = undisturbed_field(log.t, log.mag, down, None, checks, settle_s=params.mag_settle_s or 0.0,
                                   tau_s=0.0 if offline else params.mag_check_tau_s,
                                   learn_tau_s=None if offline else params.mag_reference_tau_s,
                                   gyro=log.gyro, new_field_s=params.mag_new_field_s,
                                   first_field_s=params.mag_first_field_s)
    dt = float(np.median(log.dt))
    P0 = np.diag([0.05**2] * 3 + [params.initial_bias_sigma_rad_s**2] * 3)
    model, tilt, heading, zero_rate = _filter_parts(params, offline)
    ekf = ModelEKF(model, np.r_[q0, 0.0, 0.0, 0.0], P0, dt)
    measurements = [Measurements(tilt, log.t, accel)]
    if has_mag:
        context = np.where(good_m[:, None], log.mag, np.nan)
        measurements.append(Measurements(heading, log.t,
                                         np.full(len(log), declination_rad), context=context))
    if rest is not None:
        measurements.append(Measurements(zero_rate, log.t, np.where(rest[:, None], log.gyro, np.nan)))
    run = run_filter(ekf, log.t, _gyro_input(log, params), measurements, gate_probability=params.gate_probability,
                     engine=engine)
    held = np.isnan(log.gyro).any(axis=1)
    held[-1] = False  # the last row is never used
    return replace(run, held_input=held), model
