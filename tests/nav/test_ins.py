"""The inertial navigation EKF: its model against finite differences, physics at rest, and the
estimator on chapter 11's simulated square (accuracy against the 7-state EKF, consistency)."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.analysis.metrics import chi2_interval, nees
from quadlib.constants import G0
from quadlib.geometry import quat_conjugate, quat_from_euler, quat_multiply, quat_to_dcm, quat_to_euler, quat_to_rotvec
from quadlib.geometry.rotations import wrap_angle
from quadlib.imu import ImuLog
from quadlib.nav import InsParams, estimate_ins, imu_blocks, ins_gps_sensor, ins_model
from quadlib.quad.estimate import Quad3DParams, estimate_quad3d
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.scenario import imu_with_magnetometer, simulate_run3d
from quadlib.samples import Samples

MODEL = ins_model(0.01, 0.2, 1e-4, 1e-3)


def _state(rng):
    q = quat_from_euler(0.3, -0.2, 2.0)
    return np.concatenate([q, rng.normal(size=3), rng.normal(size=3) * 5, rng.normal(size=3) * 0.01,
                           rng.normal(size=3) * 0.1])


@pytest.mark.parametrize("dt", [0.004, 0.05])
def test_the_error_jacobian_matches_finite_differences(dt):
    rng = np.random.default_rng(3)
    x, u = _state(rng), np.r_[0.4, -0.7, 1.1, 1.0, -0.5, -9.0]
    g0 = MODEL.g(x, u, dt)
    eps = 1e-6
    fd = np.column_stack([(MODEL.residual_x(MODEL.g(MODEL.state_add(x, eps * e), u, dt), g0)
                           - MODEL.residual_x(MODEL.g(MODEL.state_add(x, -eps * e), u, dt), g0)) / (2 * eps)
                          for e in np.eye(15)])
    np.testing.assert_allclose(MODEL.G(x, u, dt), fd, atol=1e-7)


def test_a_level_imu_at_rest_stays_put():
    x = np.r_[1.0, 0, 0, 0, np.zeros(12)]
    for _ in range(100):
        x = MODEL.g(x, np.r_[0.0, 0.0, 0.0, 0.0, 0.0, -G0], 0.01)
    np.testing.assert_allclose(x[4:10], 0.0, atol=1e-12)


def test_a_tilted_imu_at_rest_stays_put_and_a_tilt_error_drifts_at_g_times_the_angle():
    q = quat_from_euler(0.2, -0.1, 1.0)
    f = quat_to_dcm(q).T @ np.array([0.0, 0.0, -G0])  # what the accelerometer reads at rest
    x = np.r_[q, np.zeros(12)]
    y = MODEL.g(x, np.r_[0.0, 0.0, 0.0, f], 1.0)
    np.testing.assert_allclose(y[4:10], 0.0, atol=1e-12)
    tilted = MODEL.state_add(x, np.r_[0.01, 0, 0, np.zeros(12)])  # 10 mrad about body x
    drift = MODEL.g(tilted, np.r_[0.0, 0.0, 0.0, f], 1.0)[4:7]
    # body x is pitched 0.1 rad out of the horizontal: only its horizontal part tilts gravity
    assert np.linalg.norm(drift) == pytest.approx(G0 * 0.01 * np.cos(0.1), rel=1e-4)


def test_the_gps_sensor_without_height_measures_five_components():
    sensor = ins_gps_sensor((1.0, 1.0, 3.0), (0.1, 0.1, 0.2), use_height=False)
    x = np.r_[1.0, 0, 0, 0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, np.zeros(6)]
    np.testing.assert_array_equal(sensor.h(x), [4.0, 5.0, 1.0, 2.0, 3.0])
    assert sensor.groups == ((0, 1), (2, 3, 4))
    np.testing.assert_allclose(np.sqrt(np.diag(sensor.R)), [1.0, 1.0, 0.1, 0.1, 0.2])


def test_imu_blocks_average_and_keep_the_block_start_times():
    t = np.arange(10) * 0.1
    gyro = np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)])
    log = ImuLog(t, gyro, np.tile([0.0, 0.0, -G0], (10, 1)))
    tb, u = imu_blocks(log, 3)
    np.testing.assert_allclose(tb, [0.0, 0.3, 0.6])
    np.testing.assert_allclose(u[:, 0], [1.0, 4.0, 7.0])
    with pytest.raises(ValueError, match=r"decimate: expected an int in \[1, 5\]"):
        imu_blocks(log, 6)


def test_bad_inputs_are_named():
    log = ImuLog(np.arange(50) * 0.01, np.zeros((50, 3)), np.tile([0.0, 0.0, -G0], (50, 1)))
    with pytest.raises(ValueError, match=r"gps: expected samples of \[pn, pe, pd, vn, ve, vd\]"):
        estimate_ins(log, Samples(np.r_[0.0], np.zeros((1, 3))))
    with pytest.raises(ValueError, match="gps: expected at least one fix within"):
        estimate_ins(log, Samples(np.r_[5.0], np.zeros((1, 6))))
    with pytest.raises(TypeError, match="params: expected"):
        estimate_ins(log, Samples(np.r_[0.0], np.zeros((1, 6))), params={"gyro_sigma_rad_s": 0.1})
    with pytest.raises(ValueError, match="InsParams.gps_delay_s"):
        InsParams(gps_delay_s=-0.1)


# --- chapter 11's square, 20 flights: the INS against the 7-state EKF and against the truth ----------

SIM_PARAMS = InsParams(gyro_sigma_rad_s=0.5, accel_sigma_m_s2=(0.5, 0.5, 1.5), gps_pos_sigma_m=(0.7, 0.7, 2.0),
                       gps_vel_sigma_m_s=(0.1, 0.1, 0.3), baro_sigma_m=0.5, heading_sigma_rad=0.05)
"""The simulator's sensors (SensorNoise3D); the heading's σ is its field noise over the horizontal field."""


def _square_flights(n_flights, params, seed=8, offline=False):
    flight, noise, rng, quad3d = square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(seed), \
        Quad3DParams()
    rows = []
    for _ in range(n_flights):
        run = simulate_run3d(flight, noise, rng, decimate=10)
        x0 = run.truth[0] + rng.normal(size=7) * np.sqrt(np.diag(quad3d.P0))
        ekf = estimate_quad3d(run.t, run.u, run.gps, run.mag, x0, quad3d)
        log = imu_with_magnetometer(run, flight, noise, rng)
        ins = estimate_ins(log, run.gps, run.baro, params, decimate=10, baro_offset_m=0.0, offline=offline)
        k = np.searchsorted(flight.t, ins.t)
        d_theta = quat_to_rotvec(quat_multiply(quat_conjugate(flight.q_nb[k]), ins.x[:, :4]))
        error = np.hstack([d_theta, ins.x[:, 4:7] - flight.vel[k], ins.x[:, 7:10] - flight.pos[k]])
        euler = wrap_angle(np.column_stack(quat_to_euler(ins.x[:, :4])) - flight.euler[k])
        rows.append(dict(error=error, P=ins.P[:, :9, :9], sigma=ins.sigma[:, :9], ins_roll_pitch=euler[:, :2],
                         ekf_pos=ekf.x[:, :3] - run.truth[:, :3], ekf_vel=ekf.x[:, 3:6] - run.truth[:, 3:6],
                         cf_roll_pitch=run.roll_pitch - run.true_roll_pitch))
    return rows


def _rms(rows, key, cols=slice(None)):
    return float(np.sqrt(np.mean(np.concatenate([r[key][:, cols] for r in rows]) ** 2)))


@pytest.fixture(scope="module")
def tilt_aware_flights():
    return _square_flights(20, replace(SIM_PARAMS, heading_tilt_aware=True))


def test_the_ins_beats_the_7_state_ekf_on_chapter_8s_square(tilt_aware_flights):
    rows = tilt_aware_flights
    assert _rms(rows, "error", slice(6, 9)) < 0.7 * _rms(rows, "ekf_pos")  # measured 0.11 m against 0.22 m
    assert _rms(rows, "error", slice(3, 6)) < 0.9 * _rms(rows, "ekf_vel")  # 0.071 m/s against 0.094 m/s
    assert _rms(rows, "ins_roll_pitch") < 0.5 * _rms(rows, "cf_roll_pitch")  # 1.1° against 2.9°


def test_the_tilt_aware_ins_is_consistent_over_20_flights(tilt_aware_flights):
    rows = tilt_aware_flights
    mean_nees = np.mean([nees(r["error"], r["P"]) for r in rows], axis=0)  # over the flights, per step
    low, high = chi2_interval(9, len(rows))
    assert low < float(np.mean(mean_nees)) < high  # measured 8.1 in [7.3, 10.9]
    inside = np.mean(np.concatenate([np.abs(r["error"]) <= r["sigma"] for r in rows]))
    assert 0.60 < inside < 0.75  # ±1σ holds 72 %


def test_the_heading_only_update_trusts_its_heading_too_much_on_this_gyro():
    rows = _square_flights(4, SIM_PARAMS)
    yaw = np.concatenate([nees(r["error"][:, 2:3], r["P"][:, 2:3, 2:3]) for r in rows])
    assert np.mean(yaw) > 3.0  # the tilt's share of the measured heading is missing from its variance


def test_the_smoother_is_more_accurate_than_the_filter():
    forward, smoothed = _square_flights(3, SIM_PARAMS, seed=4), _square_flights(3, SIM_PARAMS, seed=4, offline=True)
    for cols in (slice(0, 3), slice(3, 6), slice(6, 9)):
        assert _rms(smoothed, "error", cols) < 0.9 * _rms(forward, "error", cols)
    sigma_ratio = np.concatenate([s["sigma"] / f["sigma"] for s, f in zip(smoothed, forward, strict=True)])
    assert sigma_ratio.max() < 1.5  # (the forward passes differ: offline, the heading also corrects the gyro bias)
