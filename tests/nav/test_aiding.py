"""Scan matching in the INS: the whitened pose measurement, and GPS-denied flights through a room
and down a corridor."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib import ModelEKF, Sensor
from quadlib.geometry.quaternion import quat_from_euler, quat_multiply
from quadlib.nav import (
    InsParams,
    ins_pose_sensor,
    match_poses,
    navigate,
    pose_measurements,
    sim_params,
    simulate_denied_flight,
)
from quadlib.perception import MapMatch, corridor_map, room_map
from quadlib.quad import SensorNoise3D, square_course, straight_course
from quadlib.samples import Samples


def _ekf(yaw=0.3):
    x0 = np.concatenate([quat_from_euler(0.0, 0.0, yaw), np.zeros(3), [2.0, -1.0, -3.0], np.zeros(6)])
    P0 = np.diag(np.r_[0.01, 0.01, 0.1, 0.1, 0.1, 0.1, 1.0, 2.0, 1.0, np.full(6, 1e-4)])
    P0[6, 7] = P0[7, 6] = 0.5
    return ModelEKF(InsParams().model(), x0, P0, 0.01)


def _match(pose, information):
    return MapMatch(pose=np.asarray(pose, float), information=np.asarray(information, float), rmse=0.01,
                    iterations=3, converged=True)


def test_the_whitened_update_equals_one_with_the_inverse_information():
    info = np.array([[40.0, 10.0, 2.0], [10.0, 30.0, -1.0], [2.0, -1.0, 900.0]])
    match = _match([2.5, -0.6, 0.35], info)
    m = pose_measurements([0.0], [match])
    whitened = _ekf()
    whitened.update_sensor(m.sensor, m.z[0], context=m.context[0])
    plain = Sensor("pose", ("n", "e", "yaw"), h=lambda x: np.array([x[7], x[8], np.arctan2(
        *(lambda q: (2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2)))(x[:4]))]),
        H=lambda x: m.sensor.H(x, np.r_[0.0, np.eye(3).ravel()]), R=np.linalg.inv(info))
    direct = _ekf()
    direct.update_sensor(plain, match.pose)
    np.testing.assert_allclose(whitened.nominal, direct.nominal, atol=1e-12)
    assert not np.allclose(whitened.nominal, _ekf().nominal)  # it did move
    np.testing.assert_allclose(whitened.P, direct.P, atol=1e-12)


def test_a_direction_without_information_is_left_alone():
    match = _match([5.0, 3.0, 0.3], np.diag([0.0, 100.0, 0.0]))  # a corridor along north: east only
    m = pose_measurements([0.0], [match])
    ekf = _ekf()
    before = ekf.nominal.copy()
    ekf.update_sensor(m.sensor, m.z[0], context=m.context[0])
    assert ekf.nominal[8] == pytest.approx(before[8] + (3.0 - before[8]) * 100.0 * 2.0 / (1 + 100.0 * 2.0))
    # north moves only through its correlation with east; with that removed, not at all
    ekf2 = _ekf()
    ekf2.P[6, 7] = ekf2.P[7, 6] = 0.0
    ekf2.update_sensor(m.sensor, m.z[0], context=m.context[0])
    assert ekf2.nominal[7] == pytest.approx(2.0, abs=1e-12)


def test_the_yaw_innovation_never_jumps_by_two_pi():
    ekf = _ekf(yaw=-3.1)
    m = pose_measurements([0.0], [_match([2.0, -1.0, 3.1], np.diag([1.0, 1.0, 1e4]))])
    innovation = ekf.update_sensor(m.sensor, m.z[0], context=m.context[0])
    assert abs(innovation.y[2]) / 100.0 == pytest.approx(2 * np.pi - 6.2, abs=1e-9)


def test_the_jacobian_matches_finite_differences():
    sensor = ins_pose_sensor()
    c = np.r_[0.3, np.diag([2.0, 3.0, 5.0]).ravel()]
    x = _ekf().nominal.copy()
    H, eps = sensor.H(x, c), 1e-7
    for i in range(4, 16):
        dx = np.zeros(16)
        dx[i] = eps
        np.testing.assert_allclose(H[:, i], (sensor.h(x + dx, c) - sensor.h(x - dx, c)) / (2 * eps), atol=1e-6)
    turned = x.copy()  # level: a turn about body z is a turn about the vertical, the yaw's only Jacobian
    turned[:4] = quat_multiply(x[:4], [np.cos(eps / 2), 0.0, 0.0, np.sin(eps / 2)])
    np.testing.assert_allclose(H @ (turned - x) / eps, (sensor.h(turned, c) - sensor.h(x, c)) / eps, atol=1e-6)
    np.testing.assert_allclose((sensor.h(turned, c) - sensor.h(x, c)) / eps, [0.0, 0.0, 5.0], atol=1e-6)


def test_pose_measurements_mark_missing_matches_and_reject_others():
    m = pose_measurements([0.0, 0.1], [None, _match([1.0, 2.0, 0.0], np.eye(3))])
    assert np.isnan(m.z[0]).all() and np.allclose(m.z[1], [1.0, 2.0, 0.0])
    with pytest.raises(ValueError, match="matches: expected one per time"):
        pose_measurements([0.0], [None, None])
    with pytest.raises(TypeError, match=r"matches\[0\]: expected a MapMatch"):
        pose_measurements([0.0], [np.zeros(3)])


@pytest.fixture(scope="module")
def square():
    walls = room_map(16.0, 16.0, pillars=2, boxes=[(5.0, 13.0, 7.0, 16.0)]) - 3.0
    return simulate_denied_flight(square_course(leg_s=6.0, turn_s=2.0), walls, np.random.default_rng(0),
                                  noise=SensorNoise3D(gyro_bias_rad_s=(0.01, -0.01, 0.005)))


def _horizontal_error(run, result):
    k = np.searchsorted(run.flight.t, result.t)
    return result.x[:, 7:9] - run.flight.pos[k, :2]


def test_scan_matching_holds_a_gps_denied_flight_within_a_metre(square):
    assert square.flight.t[-1] >= 30.0
    scans = np.linalg.norm(_horizontal_error(square, navigate(square, "scans")), axis=1)
    drift = np.linalg.norm(_horizontal_error(square, navigate(square, "none")), axis=1)
    assert scans.max() < 1.0 and drift[-1] > 20.0
    tracked = match_poses(square.matches)
    assert np.isfinite(tracked).all()


def test_navigate_gates_at_the_params_gate_probability(square):
    z = square.gps.z.copy()
    z[50:53, :3] += 25.0  # three fixes 25 m off
    jumped = replace(square, gps=Samples(square.gps.t, z))
    params = sim_params(square.noise)
    gated = navigate(jumped, "gps", replace(params, gate_probability=0.9999))
    ungated = navigate(jumped, "gps", replace(params, gate_probability=None))
    assert gated.sensors["gps"].rejected.sum() >= 3 and not ungated.sensors["gps"].rejected.any()
    gated_error = np.linalg.norm(_horizontal_error(square, gated), axis=1).max()
    ungated_error = np.linalg.norm(_horizontal_error(square, ungated), axis=1).max()
    assert gated_error < 0.5 < ungated_error


def test_a_corridor_fixes_the_cross_track_position_only():
    run = simulate_denied_flight(straight_course(30.0, 30.0), corridor_map(60.0, 3.0) - [10.0, 1.5],
                                 np.random.default_rng(1))
    info = run.matches[100].information
    assert np.linalg.eigvalsh(info)[0] < 1e-9 * np.linalg.eigvalsh(info)[-1]  # along the corridor: nothing
    error = _horizontal_error(run, navigate(run, "scans"))
    assert np.abs(error[:, 1]).max() < 0.1 and np.abs(error[:, 0]).max() > 2.0
