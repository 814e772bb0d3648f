"""The compiled engine gives what the readable loop gives, for every estimator that runs on it.

Each case runs one filter over the same hard log twice — ``run_filter(..., engine="compiled")`` and
``engine="readable"`` — and requires the same states, covariances and sensor traces to 1e-10 (the
VQF way of keeping two implementations one). The log has dropouts in every stream, held gyro rows,
a clipped gyro, a frozen accelerometer, a repeated timestamp, a field turned away and a push that
the χ² gates reject for long enough to reset, and a sensor gated as two groups. The public entry
points (Kesten's filters, the orientation MEKF and its smoother) are compared the same way, and a
model a user changed gives the changed model's answer. The fixed-wing EKFs and error-state UKF run
on a flight of their own, with a failed pitot (tests/fixedwing/test_compiled.py compares their entry
point too), chapter 11's quadrotor EKF and UKF on a square course with GPS jumps
(tests/quad/test_compiled.py compares estimate_quad3d), and the inertial navigation EKF, whose grid
is the IMU's rather than a sensor's, on the PX4 flight with faults added (tests/nav/test_compiled.py).
"""

from dataclasses import replace

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, rts_smooth, run_filter
from quadlib.attitude.bias_model import additive_attitude_bias_model, attitude_bias_model
from quadlib.attitude.checks import SensorChecks
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.orientation import (
    OrientationParams,
    gravity_sensor,
    heading_sensor,
    orientation_run,
    zero_rate_sensor,
)
from quadlib.attitude.tumble import random_rotation, with_spin
from quadlib.constants import earth_field_ned
from quadlib.data import load_broad_trial
from quadlib.engine import Kernel
from quadlib.fixedwing import (
    FixedWingNoise,
    error_state_ukf,
    fixedwing_flight,
    fixedwing_mag_sensor,
    fixedwing_measurements,
    fixedwing_samples,
    initial_state,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.geometry.quaternion import quat_from_rotvec, quat_multiply, quat_to_dcm
from quadlib.imu import ImuLog, ImuNoise
from quadlib.kernels import attitude as attitude_maths
from quadlib.quad import Quad3DParams, SensorNoise3D, quad3d_ekf, quad3d_ukf, simulate_run3d, square_course
from quadlib.sim.imu import imu_samples

FIELD = earth_field_ned(50.0, np.radians(65.0))


def _hard_log() -> tuple[ImuLog, float]:
    """8 s of tumbling at 100 Hz with a gyro bias, 5 % of every stream missing, a field turned by 40°
    for 0.8 s, a 1.5 m/s² push for 0.8 s, an accelerometer frozen for 6 samples, one timestamp repeated
    within its precision, and a gyro clipped at 0.8 of its largest rate."""
    motion = random_rotation(8.0, 100.0, np.random.default_rng(5), rms_rate_rad_s=1.0)
    noise = ImuNoise(gyro_sigma_rad_s=0.002, gyro_bias_rad_s=(0.004, -0.003, 0.002), accel_sigma_m_s2=0.05,
                     mag_sigma=0.3)
    log = imu_samples(motion, noise, np.random.default_rng(6), field_n=FIELD)
    rng = np.random.default_rng(7)
    t, gyro, accel, mag = log.t.copy(), log.gyro.copy(), log.accel.copy(), log.mag.copy()
    for stream in (gyro, accel, mag):
        stream[rng.random(len(log)) < 0.05] = np.nan
    gyro[0] = log.gyro[0]  # a held gyro row needs a first one to hold
    turned = (t > 3.0) & (t < 3.8)
    mag[turned] = mag[turned] @ quat_to_dcm(quat_from_rotvec([0.0, 0.0, np.radians(40.0)])).T
    accel[(t > 6.0) & (t < 6.8)] += [1.5, 0.0, 0.0]
    accel[200:206] = log.accel[200]  # frozen
    t[300] = t[299] + 1e-15  # later, but not by more than the times' precision: a repeat
    gyro_range = 0.8 * float(np.nanmax(np.abs(gyro)))
    start = quat_multiply(motion.q_nb[0], quat_from_rotvec([0.05, -0.08, 0.1]))  # 8° off the truth
    return ImuLog(t, np.clip(gyro, -gyro_range, gyro_range), accel, mag), gyro_range, start


LOG, GYRO_RANGE, Q0 = _hard_log()


# the log's own noise and field, so that the gates reject the disturbances rather than every sample
KESTEN_NOISE = AttitudeNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3, field_gauss=50.0,
                             inclination_rad=np.radians(65.0), gyro_range_rad_s=GYRO_RANGE)


def _kesten(name: str, noise: AttitudeNoise = KESTEN_NOISE, reset_after_s: float | None = 0.3, **model_changes):
    """Kesten's filter ``name`` as run_attitude_filter builds it, its sensors gated and reset after 0.3 s."""
    filt = FILTERS[name](noise, sigma0_rad=0.5)
    model = replace(filt.model, **model_changes) if model_changes else filt.model
    sensors = [replace(s, reset_after_s=reset_after_s) for s in filt.sensors]
    measurements = [Measurements(s, LOG.t, z) for s, z in zip(sensors, filt.samples(LOG), strict=True)]
    return lambda: ModelEKF(model, filt.state_from_q(Q0), filt.P0, 0.01), LOG.gyro, measurements, 0.99


def _orientation(model, heading, groups: tuple = (), reset_after_s: float | None = 0.5, agree: bool = False):
    """An attitude-and-bias filter with gravity (gated as ``groups``, reset after ``reset_after_s``, once
    the refused readings agree when ``agree``), a heading, and a zero-rate update over the first second."""
    gravity = replace(gravity_sensor(0.2), groups=groups, reset_after_s=reset_after_s, stuck_samples=3,
                      reset_needs_agreement=agree)
    still = np.where((LOG.t < 1.0)[:, None], LOG.gyro, np.nan)
    measurements = [Measurements(gravity, LOG.t, LOG.accel),
                    Measurements(heading, LOG.t, np.zeros(len(LOG)), context=LOG.mag),
                    Measurements(zero_rate_sensor(1.0), LOG.t, still)]  # loose: the sensor is not at rest
    P0 = np.diag([0.05**2] * 3 + [0.01**2] * 3) if model.is_error_state else np.diag([0.02**2] * 4 + [0.01**2] * 3)
    return lambda: ModelEKF(model, np.r_[Q0, 0.0, 0.0, 0.0], P0, 0.01), LOG.gyro, measurements, 0.99


# A reset widens P by central differences of h with steps of 1e-6: the two loops' states, equal to
# a unit in the last place before it, differ by up to ~1e-5 of that after it. The cases keep the
# resets whose result stays well inside 1e-10: QF's residual, an arc cosine, is flat where its two
# directions meet (so QF is gated without resets), and a reset of the MEKF's heading (a 40° turn
# of the field, widened by 0.5 rad²) lands at 3e-11, so the MEKF cases reset gravity only.
CASES = {name: (lambda name=name: _kesten(name, reset_after_s=None if name == "QF" else 0.3)) for name in FILTERS}
CASES |= {
    "TQF, thesis's noise": lambda: _kesten("TQF", replace(KESTEN_NOISE, thesis_process_noise=True)),
    "QKF changed: Q × 100 (a kernel with other parameters)": lambda: _kesten(
        "QKF", Q=Kernel("Q", attitude_maths.gyro_noise, [KESTEN_NOISE.gyro_sigma_rad_s, 0.0, 25.0, 4, 0.0, 0])),
    # gravity gated as two groups, tilt (x, y) and z: a reset of z alone, which hardly moves with the
    # tilt when level, would widen P by 1e3 and the rounding with it; so these two groups are not reset
    "MEKF, gravity in two groups": lambda: _orientation(attitude_bias_model(0.005, 1e-4, GYRO_RANGE),
                                                        heading_sensor(0.1), ((0, 1), (2,)), None),
    "MEKF": lambda: _orientation(attitude_bias_model(0.005, 1e-4, GYRO_RANGE), heading_sensor(0.1)),
    "MEKF, gravity reset once the refused readings agree": lambda: _orientation(
        attitude_bias_model(0.005, 1e-4, GYRO_RANGE), heading_sensor(0.1), agree=True),
    "MEKF, tilt-aware heading": lambda: _orientation(attitude_bias_model(0.005, 1e-4),
                                                     heading_sensor(0.1, tilt_aware=True)),
    "MEKF, heading corrects the bias": lambda: _orientation(attitude_bias_model(0.005, 1e-4, GYRO_RANGE),
                                                            heading_sensor(0.1, corrects_bias=True)),
    "additive attitude and bias": lambda: _orientation(additive_attitude_bias_model(0.005, 1e-4, GYRO_RANGE),
                                                       heading_sensor(0.1, corrects_bias=True)),
}


def _fixedwing_log() -> ImuLog:
    """40 s of Salmony's flight at 25 Hz with 5 % of every stream missing, the pitot out for 10 s,
    the magnetometer turned by 30° for 3 s and a 4 m/s² push for 1 s."""
    noise = FixedWingNoise()
    log = fixedwing_samples(fixedwing_flight(rate_hz=25.0), noise, np.random.default_rng(3)).slice(0, 1000)
    rng = np.random.default_rng(4)
    gyro, accel, mag, airspeed = (np.array(a) for a in (log.gyro, log.accel, log.mag, log.airspeed))
    for stream in (gyro, accel, mag, airspeed):
        stream[rng.random(len(log)) < 0.05] = np.nan
    gyro[:60], accel[:60], mag[:60] = log.gyro[:60], log.accel[:60], log.mag[:60]  # a still start
    airspeed[(log.t > 10.0) & (log.t < 20.0)] = np.nan
    turned = (log.t > 25.0) & (log.t < 28.0)
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    mag[turned] = mag[turned] @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    accel[(log.t > 32.0) & (log.t < 33.0)] += [4.0, 0.0, 0.0]
    return ImuLog(log.t, gyro, accel, mag, airspeed)


FIXEDWING = _fixedwing_log()


def _fixedwing(factory, reset_after_s: float | None = 1.0):
    """A fixed-wing filter as estimate_fixedwing_attitude builds it, its magnetometer reset after
    ``reset_after_s``."""
    noise = FixedWingNoise()
    x0 = initial_state(FIXEDWING, 50)
    mag = replace(fixedwing_mag_sensor(noise.declination_rad, noise.mag_sigma, noise.inclination_rad),
                  reset_after_s=reset_after_s)
    measurements = fixedwing_measurements(FIXEDWING, noise.accel_sigma_m_s2, mag)
    return lambda: factory(x0, noise, 0.04), FIXEDWING.gyro, measurements, 0.999


# On the error-state filters the magnetometer's reset, whose central differences magnify the last
# bits, leaves an NIS 1.4e-9 apart (sample 726); their resets are compared on the MEKF's gravity and
# the quadrotor's GPS instead.
CASES |= {"fixed-wing Salmony EKF": lambda: _fixedwing(salmony_ekf),
          "fixed-wing multiplicative EKF": lambda: _fixedwing(multiplicative_ekf, reset_after_s=None),
          "fixed-wing error-state UKF": lambda: _fixedwing(error_state_ukf, reset_after_s=None)}


def _quad3d_log():
    """Chapter 11's square course at 50 Hz with GPS at 10 Hz and headings at 100 Hz: 10 % of the headings
    and 5 % of the inputs missing, a heading repeated, a GPS jump of 30 m for 0.5 s and one of 15 m that
    stays (the position group is reset after 1 s)."""
    run = simulate_run3d(square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(8),
                         decimate=10, tau=5.0)
    rng = np.random.default_rng(9)
    gps_z, mag_t, mag_z, u = run.gps.z.copy(), run.mag.t.copy(), run.mag.z.copy(), run.u.copy()
    gps_z[40:45, :3] += 30.0
    gps_z[100:, 1] += 15.0
    mag_z[rng.random(mag_t.size) < 0.1] = np.nan
    mag_t[501] = mag_t[500]
    u[1:][rng.random(u.shape[0] - 1) < 0.05] = np.nan
    return run.t, u, (run.gps.t, gps_z), (mag_t, mag_z), run.truth[0] + np.r_[3.0, 0, 0, 0, 0, 0, 0.5]


QUAD3D = _quad3d_log()


def _quad3d(factory):
    """Chapter 11's EKF or UKF as estimate_quad3d builds it, gated."""
    t, u, gps, mag, x0 = QUAD3D
    gps_sensor, mag_sensor = Quad3DParams().sensors()
    measurements = [Measurements(gps_sensor, *gps), Measurements(mag_sensor, *mag)]
    return lambda: factory(x0, 0.02), u, measurements, 0.999


CASES |= {"3D quadrotor EKF": lambda: _quad3d(quad3d_ekf), "3D quadrotor UKF": lambda: _quad3d(quad3d_ukf)}


@pytest.mark.parametrize("case", list(CASES))
def test_the_engine_equals_the_readable_loop(case, assert_same_run):
    make, u, measurements, gate = CASES[case]()
    on_engine, readable = make(), make()
    t = QUAD3D[0] if case.startswith("3D") else measurements[0].t
    compiled = run_filter(on_engine, t, u, measurements, gate, engine="compiled")
    assert compiled.engine == "compiled"
    expected = run_filter(readable, t, u, measurements, gate, engine="readable")
    assert expected.engine == "readable"
    assert_same_run(compiled, expected)
    # the filter is left where the readable one is, and goes on from there alike
    for f in (on_engine, readable):
        f.predict(u[-2], 0.01)
    np.testing.assert_allclose(on_engine.estimate, readable.estimate, rtol=0, atol=1e-10)
    np.testing.assert_allclose(on_engine.P, readable.P, rtol=0, atol=1e-10)


@pytest.mark.parametrize("case", list(CASES))
def test_the_engines_smoother_equals_the_readable_one(case, assert_same_run):
    """The RTS backward pass over each forward run (whatever a gate or a consider update did to it)."""
    make, u, measurements, gate = CASES[case]()
    filt = make()
    forward = run_filter(filt, QUAD3D[0] if case.startswith("3D") else measurements[0].t, u, measurements, gate)
    compiled = rts_smooth(filt.model, forward, u, engine="compiled")
    assert compiled.engine == "compiled"
    assert_same_run(compiled, rts_smooth(filt.model, forward, u, engine="readable"))


def test_the_cases_reach_every_branch():
    """The comparisons above are only worth something if each branch happened in them."""
    make, u, measurements, gate = CASES["MEKF"]()
    run = run_filter(make(), LOG.t, u, measurements, gate)
    gravity, heading = run.sensors["gravity"], run.sensors["heading"]
    for trace in (gravity, heading):
        assert trace.rejected.sum() > 5 and trace.missing.sum() > 20 and trace.duplicate[300]
    assert gravity.reset.sum() >= 1
    make, u, measurements, gate = CASES["MEKF, gravity reset once the refused readings agree"]()
    agreeing = run_filter(make(), LOG.t, u, measurements, gate).sensors["gravity"]
    assert agreeing.reset.any()  # the push's readings agree (BROAD 34's below do not)
    make, u, measurements, gate = CASES["MEKF, gravity in two groups"]()
    split = run_filter(make(), LOG.t, u, measurements, gate).sensors["gravity"]
    assert (split.rejected & split.used).sum() > 3  # one group rejected, the other used
    assert gravity.missing[202:206].all() and not gravity.missing[201]  # the frozen accelerometer
    assert run.held_input.sum() > 20 and run.sensors["zero rate"].used.sum() > 30
    assert (np.abs(LOG.gyro) >= 0.999 * GYRO_RANGE).any(axis=1).sum() > 20  # saturated steps
    make, u, measurements, gate = CASES["QF"]()
    kesten = run_filter(make(), LOG.t, u, measurements, gate)
    assert kesten.sensors["mag"].rejected.any() and kesten.sensors["accel"].rejected.any()
    make, u, measurements, gate = CASES["QKF"]()
    kesten = run_filter(make(), LOG.t, u, measurements, gate)
    assert kesten.sensors["mag"].reset.any() and kesten.sensors["accel"].reset.any()
    make, u, measurements, gate = CASES["fixed-wing Salmony EKF"]()
    fixedwing = run_filter(make(), FIXEDWING.t, u, measurements, gate).sensors
    assert fixedwing["mag"].reset.any() and fixedwing["accel"].rejected.any()
    assert fixedwing["accel (no airspeed)"].used.sum() > 100  # the failed pitot
    make, u, measurements, gate = CASES["3D quadrotor UKF"]()
    quad = run_filter(make(), QUAD3D[0], u, measurements, gate)
    assert quad.sensors["gps"].reset.any() and (quad.sensors["gps"].rejected & quad.sensors["gps"].used).any()
    assert quad.sensors["mag"].duplicate[501] and quad.sensors["mag"].missing.sum() > 100 and quad.held_input.any()


def test_a_changed_model_gives_the_changed_models_answer():
    """A QKF whose Q a user multiplied by 100 in plain Python runs on the readable loop, says so, and
    gives the changed model's estimate, not the original one's."""
    noise = AttitudeNoise()
    log = imu_samples(with_spin(random_rotation(4.0, 250.0, np.random.default_rng(11)), 1.5, 0.5, 6.0), noise,
                      np.random.default_rng(12), field_n=noise.field_n)
    qkf = FILTERS["QKF"](noise)
    original = qkf.model.Q
    changed = qkf._replace(model=replace(qkf.model, Q=lambda dt: 100 * original(dt)))
    run = run_attitude_filter(changed, log)
    assert run.run.engine == "readable" and "Q" in run.run.engine_note
    np.testing.assert_allclose(run.q_nb, run_attitude_filter(changed, log, compiled=False).q_nb, rtol=0, atol=1e-12)
    unchanged = run_attitude_filter(qkf, log)
    assert unchanged.run.engine == "compiled"
    assert np.abs(run.q_nb - unchanged.q_nb).max() > 1e-4
    with pytest.raises(ValueError, match="engine: expected a filter the compiled engine can run.*Q is plain Python"):
        run_filter(ModelEKF(changed.model, Q0, qkf.P0, 0.004), log.t, log.gyro, [], engine="compiled")


KESTEN_NOISES = {"corrected noise, saturating gyro": AttitudeNoise(gyro_range_rad_s=GYRO_RANGE),
                 "thesis's noise": AttitudeNoise(thesis_process_noise=True)}


@pytest.mark.parametrize("noise", list(KESTEN_NOISES))
@pytest.mark.parametrize("name", list(FILTERS))
def test_run_attitude_filter_equals_its_readable_run(name, noise, assert_same_run):
    filt = FILTERS[name](KESTEN_NOISES[noise], sigma0_rad=0.5)
    log = ImuLog(LOG.t, LOG.gyro, LOG.accel, LOG.mag * (0.5 / 50.0))  # Kesten's field is 0.5 G
    compiled, readable = run_attitude_filter(filt, log, Q0), run_attitude_filter(filt, log, Q0, compiled=False)
    assert compiled.run.engine == "compiled"
    assert_same_run(compiled.run, readable.run)
    np.testing.assert_allclose(compiled.q_nb, readable.q_nb, rtol=0, atol=1e-10)


TURNS = fixedwing_samples(fixedwing_flight(rate_hz=50.0), FixedWingNoise(), np.random.default_rng(12))
ORIENTATION = {
    "BROAD slice": (load_broad_trial("24_disturbed_tapping_A").log.slice(0, 2500), OrientationParams()),
    "hard log, tight gate": (LOG, OrientationParams(gate_probability=0.9, gyro_range_rad_s=GYRO_RANGE,
                                                    gravity_sigma_m_s2=0.2, accel_tau_s=None)),
    "no magnetometer, no rest, no gate": (ImuLog(LOG.t, LOG.gyro, LOG.accel),
                                          OrientationParams(gate_probability=None, rest_min_s=None)),
    # gravity ungated, the turns' acceleration tilts the estimate and turns its heading away: headings reset
    # once they agree
    "fixed-wing turns": (TURNS, OrientationParams(gravity_reset_s=None)),
    # gravity refused through the turns, and reset after 2 s of it
    "fixed-wing turns, gravity reset": (TURNS, OrientationParams(gravity_reset_s=2.0)),
    # 30-75 s of a magnet turning with the sensor: headings refused for seconds without agreeing, one reset
    "BROAD 34, a magnet turning with the sensor": (
        load_broad_trial("34_disturbed_attached_magnet_3cm").log.slice(8571, 21429),
        OrientationParams(checks=SensorChecks())),  # the strength at 20 %: the gate, not the checks, sees the magnet
}


def _refused_past(trace, seconds: float) -> int:
    """The samples a lock-out still refused after ``seconds`` (a reset that waits for agreement)."""
    since, count = None, 0
    for k in np.flatnonzero(~(trace.missing | trace.duplicate)):
        locked = trace.rejected[k] and not trace.reset[k]
        since = (trace.t[k] if since is None else since) if locked else None
        count += locked and trace.t[k] - since >= seconds
    return count


@pytest.mark.parametrize("offline", [False, True], ids=["forward", "smoother"])
@pytest.mark.parametrize("case", list(ORIENTATION))
def test_orientation_run_equals_its_readable_run(case, offline, assert_same_run):
    log, params = ORIENTATION[case]
    compiled = orientation_run(log, params, offline=offline)
    assert compiled.engine == "compiled"
    heading = compiled.sensors.get("heading")
    if case == "fixed-wing turns":
        assert heading.reset.sum() >= 5
    if case == "fixed-wing turns, gravity reset":
        assert compiled.sensors["gravity"].reset.sum() >= 2
    if case.startswith("BROAD 34") and not offline:  # offline judges each reading alone: other lock-outs
        assert heading.reset.any() and _refused_past(heading, params.heading_reset_s) > 100
    assert_same_run(compiled, orientation_run(log, params, offline=offline, compiled=False))
