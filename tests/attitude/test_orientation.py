"""The orientation MEKF: a slice of a real BROAD trial, a known gyro bias, a magnet, and its inputs."""

import numpy as np
import pytest

from quadlib.analysis.metrics import attitude_error, broad_errors
from quadlib.attitude.checks import SensorChecks
from quadlib.attitude.lowpass import inertial_lowpass
from quadlib.attitude.orientation import OrientationParams, estimate_orientation, orientation_run
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.data import load_broad_trial
from quadlib.geometry.quaternion import quat_to_dcm
from quadlib.imu import ImuLog, ImuNoise
from quadlib.replay import FilterRun
from quadlib.sim.imu import BodyMotion, imu_samples


def test_a_slice_of_a_real_trial_is_tracked_to_a_few_degrees():
    trial = load_broad_trial("02_undisturbed_slow_rotation_B")
    n = 3000  # the first 10.5 s: rest, then slow rotations
    q = estimate_orientation(trial.log.slice(0, n)).q
    errors = broad_errors(q, trial.q_nb[:n])  # every sample of the slice, at rest or moving
    assert errors["total_deg"] < 3.0 and errors["inclination_deg"] < 2.0


FIELD = earth_field_ned(50.0, np.radians(65.0))
MOTION = random_rotation(40.0, 100.0, np.random.default_rng(3), rms_rate_rad_s=0.5)


def test_a_constant_gyro_bias_is_estimated():
    bias = np.array([0.005, -0.004, 0.003])  # 0.2–0.3 °/s, the size of the BROAD sensors' biases
    noise = ImuNoise(gyro_sigma_rad_s=0.002, gyro_bias_rad_s=tuple(bias), accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(4), field_n=FIELD)
    run = orientation_run(log)
    np.testing.assert_allclose(run.x[-1, 4:], bias, atol=1e-3)
    # until the bias is learnt, the low-passed gravity lags by about |b − b̂| τ (3.6° at 5 s)
    assert np.degrees(attitude_error(run.x[:, :4], MOTION.q_nb))[MOTION.t > 20].max() < 1.5


def test_the_inertial_lowpass_passes_gravity_and_a_bias_tilts_it_by_bias_times_tau():
    noise = ImuNoise(gyro_sigma_rad_s=0.0, accel_sigma_m_s2=0.0, mag_sigma=0.0)
    log = imu_samples(MOTION, noise, np.random.default_rng(4))
    up = np.einsum("nji,j->ni", quat_to_dcm(MOTION.q_nb), [0.0, 0.0, -9.80665])

    def tilt_deg(gravity):
        cos = np.sum(gravity * up, axis=1) / np.linalg.norm(gravity, axis=1) / 9.80665
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))[MOTION.t > 10]

    assert tilt_deg(inertial_lowpass(log, 3.0)).max() < 0.05  # an exact gyro: gravity passes unchanged
    biased = ImuLog(log.t, log.gyro + [0.01, 0.0, 0.0], log.accel)
    lag = tilt_deg(inertial_lowpass(biased, 3.0))
    assert 0.5 * np.degrees(0.03) < np.median(lag) < 1.5 * np.degrees(0.03)  # about |b| τ = 0.03 rad
    assert tilt_deg(inertial_lowpass(biased, 3.0, [0.01, 0.0, 0.0])).max() < 0.05  # the bias removed
    assert tilt_deg(inertial_lowpass(log, 3.0, second_order=True)).max() < 0.05


def test_the_second_order_average_damps_a_shake_pi_f_tau_times_more():
    """±5 m/s² of shaking at 1 Hz, 13 times the cut-off of a 3 s average: the first-order average
    keeps about 1/(2π f τ) of it (0.26 m/s²), the second-order one about (f_c/f)² (f_c = √2/(2π τ)),
    π f τ ≈ 9.4 times less."""
    shake = 5.0 * np.sin(2 * np.pi * 1.0 * MOTION.t)[:, None] * np.array([1.0, 0.0, 0.0])
    f_b = MOTION.f_b + np.einsum("nji,nj->ni", quat_to_dcm(MOTION.q_nb), shake)
    exact = ImuNoise(gyro_sigma_rad_s=0.0, accel_sigma_m_s2=0.0, mag_sigma=0.0)
    log = imu_samples(BodyMotion(MOTION.t, MOTION.q_nb, MOTION.omega_b, f_b), exact, np.random.default_rng(4))
    up = np.einsum("nji,j->ni", quat_to_dcm(MOTION.q_nb), [0.0, 0.0, -9.80665])

    def swing(gravity):
        return np.linalg.norm(gravity - up, axis=1)[MOTION.t > 20].max()

    first, second = swing(inertial_lowpass(log, 3.0)), swing(inertial_lowpass(log, 3.0, second_order=True))
    assert 0.5 * 5.0 / (2 * np.pi * 3.0) < first < 1.5 * 5.0 / (2 * np.pi * 3.0)
    assert 0.8 * np.pi * 3.0 < first / second < 1.2 * np.pi * 3.0


def test_a_translation_does_not_tilt_the_estimate():
    """±5 m/s² of sideways shaking at 0.5 Hz while the sensor turns: the raw accelerometer's norm is
    often plausible and its direction wrong; averaged in the non-rotating frame the shaking cancels."""
    shake = 5.0 * np.sin(2 * np.pi * 0.5 * MOTION.t)[:, None] * np.array([1.0, 0.0, 0.0])  # NED north
    f_b = MOTION.f_b + np.einsum("nji,nj->ni", quat_to_dcm(MOTION.q_nb), shake)
    moving = BodyMotion(MOTION.t, MOTION.q_nb, MOTION.omega_b, f_b)
    noise = ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(moving, noise, np.random.default_rng(6), field_n=FIELD)
    def max_error(tau):
        q = estimate_orientation(log, params=OrientationParams(accel_tau_s=tau)).q
        return np.degrees(attitude_error(q, MOTION.q_nb))[MOTION.t > 10].max()

    averaged = max_error(3.0)
    # the raw accelerometer's down swings with the shaking, and the field's dip with it: the
    # magnetometer fails its checks almost always, and the caller is told
    with pytest.warns(UserWarning, match=r"^t\.mag: the heading update used \d+ of its 4001 readings"):
        raw = max_error(None)
    assert averaged < 5.0 and raw > 3 * averaged


def test_a_magnet_near_the_sensor_does_not_turn_the_heading():
    noise = ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(5), field_n=FIELD)
    mag = np.array(log.mag)
    near = (log.t > 15) & (log.t < 25)
    mag[near] += [60.0, 0.0, 0.0]  # a magnet fixed to the sensor, stronger than the Earth's field
    q = estimate_orientation(ImuLog(log.t, log.gyro, log.accel, mag)).q
    err = np.degrees(attitude_error(q, MOTION.q_nb))
    assert err[near].max() < 3.0 and err[MOTION.t > 30].max() < 2.0
    trusting = OrientationParams(gate_probability=None, checks=SensorChecks(None, None, None, None))
    believed = estimate_orientation(ImuLog(log.t, log.gyro, log.accel, mag), params=trusting).q
    assert np.degrees(attitude_error(believed, MOTION.q_nb))[near].max() > 10.0  # the checks matter


def test_arrays_take_each_gyro_row_as_the_rate_before_its_time():
    noise = ImuNoise(gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(4), field_n=FIELD).slice(0, 500)
    ending = np.vstack([np.zeros((1, 3)), log.gyro[:-1]])  # the same rates, stamped at the end of their interval
    q = estimate_orientation(log.t, ending, log.accel, log.mag).q
    assert q.shape == (500, 4)
    assert np.abs(q[:-1] - estimate_orientation(log).q[:-1]).max() < 1e-12
    assert not np.array_equal(estimate_orientation(log.t, ending, log.accel).q, q)  # no magnetometer: gyro heading


def test_the_run_names_its_parts_online_and_offline():
    log = imu_samples(MOTION, ImuNoise(mag_sigma=0.3), np.random.default_rng(4), field_n=FIELD).slice(0, 300)
    for offline in (False, True):
        run = estimate_orientation(log, offline=offline)
        assert isinstance(run, FilterRun) and run.layout == {"q": slice(0, 4), "gyro_bias": slice(4, 7)}
        np.testing.assert_array_equal(run.q, run.x[:, :4])
        np.testing.assert_array_equal(run.gyro_bias, run.x[:, 4:])
    with pytest.raises(AttributeError, match=r"state part 'p' \(parts: \['gyro_bias', 'q'\]\)"):
        run.p  # noqa: B018


def test_broad_raw_arrays_give_what_the_loader_gives():
    import h5py

    from quadlib.data import data_path

    name = "07_undisturbed_fast_rotation_B"
    with h5py.File(data_path(f"broad/{name}.hdf5"), "r") as f:
        rate = float(f.attrs["sampling_rate"])
        gyr, acc, mag = (np.asarray(f[k], dtype=float)[:20_000] for k in ("imu_gyr", "imu_acc", "imu_mag"))
    q = estimate_orientation(np.arange(len(gyr)) / rate, gyr, acc, mag).q
    loaded = estimate_orientation(load_broad_trial(name).log.slice(0, 20_000)).q
    assert np.abs(q - loaded).max() < 1e-12


def test_the_smoother_beats_the_forward_filter_where_the_bias_was_unknown():
    """The forward filter tilts by about |b| τ until it has learnt the bias; the backward pass
    carries the bias learnt later back to the start."""
    bias = np.array([0.005, -0.004, 0.003])
    noise = ImuNoise(gyro_sigma_rad_s=0.002, gyro_bias_rad_s=tuple(bias), accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(MOTION, noise, np.random.default_rng(4), field_n=FIELD)
    forward, smoothed = orientation_run(log), orientation_run(log, offline=True)
    early = (MOTION.t > 1.0) & (MOTION.t < 15.0)
    err_f, err_s = (np.degrees(attitude_error(r.x[:, :4], MOTION.q_nb)) for r in (forward, smoothed))
    assert np.sqrt(np.mean(err_s[early] ** 2)) < 0.6 * np.sqrt(np.mean(err_f[early] ** 2))  # 0.38° against 0.74°
    assert np.sqrt(np.mean(err_s**2)) < np.sqrt(np.mean(err_f**2))
    np.testing.assert_allclose(smoothed.x[: int(0.2 * len(log)), 4:], np.broadcast_to(bias, (int(0.2 * len(log)), 3)),
                               atol=1.5e-3)  # the bias is known from the first sample on
    # the start, uncertain forwards, is known backwards: the tilt well, the heading less (it is tied to
    # later headings through the integrated z-bias, which the magnetometer does not correct)
    assert (smoothed.sigma[0] < forward.sigma[0]).all() and (smoothed.sigma[0, :2] < 0.2 * forward.sigma[0, :2]).all()


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match=r"gyr: expected an array of shape \(3, 3\), got None"):
        estimate_orientation(np.arange(3.0))
    with pytest.raises(TypeError, match="log: expected an ImuLog, got tuple"):
        orientation_run((np.zeros(3), np.zeros((3, 3))))
    log = ImuLog(np.arange(3.0), np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(TypeError, match="gyr, acc, mag: expected none of them with an ImuLog"):
        estimate_orientation(log, np.zeros((3, 3)))


def test_the_heading_update_turns_about_the_vertical_only():
    from quadlib.attitude.bias_model import attitude_bias_model
    from quadlib.geometry.quaternion import quat_normalize
    from quadlib.sensors import heading_sensor

    model, sensor, rng = attitude_bias_model(0.005, 1e-4), heading_sensor(0.1), np.random.default_rng(1)
    for _ in range(20):
        x = np.r_[quat_normalize(rng.normal(size=4)), rng.normal(size=3) * 0.01]
        m_b = rng.normal(size=3) * 30
        H = sensor.H(x, m_b) @ model.add_jacobian(x)  # in error coordinates [δθ, δb]
        np.testing.assert_allclose(H[0], np.r_[quat_to_dcm(x[:4])[2], 0.0, 0.0, 0.0], atol=1e-12)
        turn = 0.01 * quat_to_dcm(x[:4])[2]  # a body turn whose earth-frame axis is down: a pure heading change
        heading_change = sensor.residual(sensor.h(model.state_add(x, np.r_[turn, 0, 0, 0]), m_b), sensor.h(x, m_b))
        assert heading_change[0] == pytest.approx(0.01, rel=1e-4)  # h changes by exactly that turn


def _still_then_turning(still_s=5.0, turning_s=10.0, rate_hz=100.0):
    """At rest, then turning at up to 1 rad/s, then at rest again."""
    from quadlib.constants import GRAVITY_N
    from quadlib.geometry.quaternion import integrate_body_rate

    t = np.arange(int((2 * still_s + turning_s) * rate_hz)) / rate_hz
    turning = (t >= still_s) & (t < still_s + turning_s)
    omega = np.where(turning[:, None], np.sin(2 * np.pi * np.outer(t - still_s, [0.1, 0.15, 0.05])), 0.0)
    q = np.empty((t.size, 4))
    q[0] = [0.9, 0.1, -0.2, 0.3] / np.linalg.norm([0.9, 0.1, -0.2, 0.3])
    for k in range(1, t.size):
        q[k] = integrate_body_rate(q[k - 1], omega[k - 1], t[k] - t[k - 1])
    f_b = np.einsum("nji,j->ni", quat_to_dcm(q), -GRAVITY_N)
    return BodyMotion(t, q, omega, f_b), turning


def test_rest_is_found_after_its_minimum_duration_and_never_while_turning():
    from quadlib.attitude.lowpass import rest_mask

    motion, turning = _still_then_turning()
    noise = ImuNoise(gyro_sigma_rad_s=0.005, gyro_bias_rad_s=(0.01, 0.0, 0.0), accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(motion, noise, np.random.default_rng(2), field_n=FIELD)
    rest = rest_mask(log, np.radians(2.0), 0.5, 1.5)
    assert not rest[turning & (motion.t > 5.2)].any()  # its first samples turn slower than the threshold
    assert rest[(motion.t > 1.6) & (motion.t < 5.0)].all() and not rest[motion.t < 1.4].any()
    assert rest[motion.t > 15.0 + 3.0].all()  # the low-passes forget the turning in about a second


def test_a_gyro_bias_is_learnt_at_rest_within_seconds():
    """The zero-rate update measures the bias directly; without it the bias is learnt only through
    the drift the accelerometer and magnetometer see, which at rest is slow."""
    motion, _ = _still_then_turning()
    bias = np.array([0.01, -0.008, 0.006])
    noise = ImuNoise(gyro_sigma_rad_s=0.005, gyro_bias_rad_s=tuple(bias), accel_sigma_m_s2=0.05, mag_sigma=0.3)
    log = imu_samples(motion, noise, np.random.default_rng(3), field_n=FIELD)
    at_4s = int(np.searchsorted(motion.t, 4.0))
    with_rest = orientation_run(log).x[at_4s, 4:]
    without = orientation_run(log, OrientationParams(rest_min_s=None)).x[at_4s, 4:]
    assert np.abs(with_rest - bias).max() < 1e-3 < np.abs(without - bias).max()


def test_the_magnetometer_turns_the_heading_and_never_the_bias():
    from quadlib import ModelEKF
    from quadlib.attitude.bias_model import attitude_bias_model
    from quadlib.geometry.quaternion import quat_from_euler
    from quadlib.sensors import heading_sensor

    x0 = np.r_[quat_from_euler(0.1, -0.2, 0.3), 0.01, -0.02, 0.005]
    P0 = np.full((6, 6), 1e-5) + np.diag([1e-2] * 3 + [1e-4] * 3)  # attitude and bias correlated
    ekf = ModelEKF(attitude_bias_model(0.005, 1e-4), x0, P0, 0.01)
    m_b = quat_to_dcm(x0[:4]).T @ [0.0, 20.0, 40.0]  # a field pointing east: a 90° heading innovation
    ekf.update_sensor(heading_sensor(0.1), [0.0], context=m_b)
    assert np.array_equal(ekf.estimate[4:], x0[4:])
    assert not np.allclose(ekf.estimate[:4], x0[:4], atol=1e-3)  # the attitude turned


def test_the_offline_pass_uses_the_ordinary_heading_update():
    from quadlib.sensors import heading_sensor

    assert heading_sensor(0.1).uncorrected == (3, 4, 5) and heading_sensor(0.1, corrects_bias=True).uncorrected == ()


def test_online_the_field_is_judged_on_its_average_offline_reading_by_reading():
    """BROAD trial 30 from 20 s to 54 s, a magnet near the board's path: online, the averaged checks
    leave out 11 % of the field readings in motion; offline, where the heading update also teaches the
    bias, each reading is judged alone and half of them are left out (measured: 11 % and 50 %)."""
    trial = load_broad_trial("30_disturbed_stationary_magnet_C")
    a, b = np.searchsorted(trial.log.t, [20.0, 54.0])
    log, moving = trial.log.slice(a, b), trial.movement[a:b]
    skipped = {offline: orientation_run(log, offline=offline).sensors["heading"].missing[moving].mean()
               for offline in (False, True)}
    assert skipped[False] < 0.15 and skipped[True] > 0.4
