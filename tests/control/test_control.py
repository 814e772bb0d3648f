"""Controllers and the closed loop: LQR against Riccati, Kesten's printed gains against his weights,
the vehicle's physics, the sign of eq. (3.11), and closed-loop flights that are deterministic."""

import numpy as np
import pytest

from quadlib.analysis.metrics import attitude_error as attitude_angle
from quadlib.control import (
    MIXER,
    AltitudeGains,
    LoopSensors,
    QuadrotorParams,
    altitude_model_matrices,
    altitude_pid_gains,
    altitude_step,
    attitude_error,
    attitude_pid_gains,
    attitude_wave,
    fly,
    fly_path,
    hover_state,
    lqr_gain,
    motor_torques,
    quadrotor_step,
    riccati_gain,
    thrust_attitude,
    tilt_angle,
)
from quadlib.geometry import quat_from_euler, quat_from_rotvec

PRINTED_ALTITUDE = AltitudeGains(c_i=-1.0, c_p=-2.9751, c_d=-3.4257)  # Kesten eqs. (4.21)–(4.23)
PRINTED_ATTITUDE = tuple(0.03 * np.diag(d) for d in ([0.2, 0.2, 0.3], [0.1, 0.1, 0.2], [0.075, 0.075, 0.0]))


def test_python_control_and_scipy_agree():
    A, B = altitude_model_matrices(1.1)
    Q, R = np.diag([4.0, 2.0, 1.0]), np.eye(1)
    np.testing.assert_allclose(lqr_gain(A, B, Q, R), riccati_gain(A, B, Q, R), rtol=0, atol=1e-9)
    K = riccati_gain(A, B, Q, R)
    assert np.all(np.linalg.eigvals(A - B @ K).real < 0)


def test_kestens_printed_gains_do_not_follow_from_his_weights():
    gains = altitude_pid_gains()  # m = 1.1 kg, Q = diag(4, 2, 1), R = 1
    assert gains.c_i == pytest.approx(-2.0, abs=1e-9)  # √(Q_e/R) in this chain of integrators
    assert abs(gains.c_p - PRINTED_ALTITUDE.c_p) > 0.5 and abs(gains.c_d - PRINTED_ALTITUDE.c_d) > 0.3
    assert altitude_pid_gains(q_e=1.0).c_i == pytest.approx(-1.0, abs=1e-9)  # the printed c_i needs Q_e = R


def test_the_vehicle_hovers_and_its_motors_turn_it_the_right_way():
    params = QuadrotorParams()
    X = hover_state(params, 2.0)
    for _ in range(250):
        X = quadrotor_step(params, X, np.full(4, params.hover_thrust_n / 4), 0.004)
    np.testing.assert_allclose(X[:3], [0.0, 0.0, -2.0], atol=1e-9)
    for axis in range(3):  # each column of MIXER turns the body positively about its axis, and only it
        torque = motor_torques(params, MIXER[:, axis])
        assert torque[axis] > 0 and np.allclose(np.delete(torque, axis), 0.0)
    assert np.allclose(MIXER.sum(axis=0), 0.0)  # eq. (3.11) leaves the total thrust unchanged


def test_tilt_and_attitude_error_follow_the_errata():
    rolled_facing_south = quat_from_euler(np.radians(10.0), 0.0, np.pi)
    assert np.degrees(tilt_angle(rolled_facing_south)) == pytest.approx(10.0, abs=1e-9)  # E33
    ref = quat_from_euler(0.0, 0.0, np.pi / 2)  # facing east
    q = quat_from_euler(np.radians(5.0), 0.0, np.pi / 2)  # rolled 5° about its own x
    np.testing.assert_allclose(attitude_error(q, ref), [np.radians(5.0), 0.0, 0.0], atol=1e-12)  # E34


def _roll_recovery(gains, roll_deg=3.0, seconds=3.0):
    params = QuadrotorParams()
    start = hover_state(params, 1.0, quat_from_rotvec([np.radians(roll_deg), 0.0, 0.0]))
    run = fly(altitude_step(t_step_s=1e9), seconds, params, attitude_gains=gains, x0=start)
    return np.degrees(attitude_angle(run.state[:, 6:10], run.q_ref))


def test_eq_3_11_with_the_printed_positive_gains_pushes_the_error_up():
    printed = _roll_recovery(PRINTED_ATTITUDE, seconds=4.0)
    assert printed[-1] > 5 * printed[0]  # E36: a 3° roll error grows (to 16° in 4 s)
    negated = _roll_recovery(tuple(-C for C in PRINTED_ATTITUDE), seconds=4.0)
    assert negated.max() <= printed[0] + 1e-9  # with the sign of E35 it swings back (slowly: the gains are small)
    lqr = _roll_recovery(attitude_pid_gains(QuadrotorParams()), seconds=4.0)
    assert lqr[-1] < 0.1 * lqr[0]


def test_figure_5_3_with_the_printed_gains():
    run = fly(altitude_step(t_step_s=2.0), 10.0, altitude_gains=PRINTED_ALTITUDE)
    after = run.t >= 2.0
    rise = run.t[after][np.argmax(run.height[after] >= 1.0 + 0.9 * 2.0)] - 2.0
    assert rise < 3.0  # "travels to the reference altitude within three seconds"
    assert 0.0 < run.height.max() - 3.0 < 0.6  # an overshoot, measured 25 %
    assert abs(run.height[-1] - 3.0) < 0.1


def test_hover_holds_altitude_with_the_true_state_after_a_disturbance():
    params = QuadrotorParams()
    start = hover_state(params, 1.0, quat_from_rotvec([np.radians(10.0), np.radians(-5.0), 0.0]))
    run = fly(altitude_step(t_step_s=1e9), 8.0, params, x0=start)
    assert np.sqrt(np.mean((run.height - 1.0) ** 2)) < 0.05
    assert np.degrees(attitude_angle(run.state[-1:, 6:10], run.q_ref[-1:]))[0] < 0.5


def test_closed_loop_runs_are_deterministic_for_a_seed():
    a = fly(attitude_wave(), 2.0, estimator="filters", rng=np.random.default_rng(5))
    b = fly(attitude_wave(), 2.0, estimator="filters", rng=np.random.default_rng(5))
    np.testing.assert_array_equal(a.state, b.state)
    np.testing.assert_array_equal(a.thrust_cmd, b.thrust_cmd)
    c = fly(attitude_wave(), 2.0, estimator="filters", rng=np.random.default_rng(6))
    assert not np.array_equal(a.state, c.state)


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match="estimator: expected 'truth', 'altitude' or 'filters'"):
        fly(altitude_step(), 1.0, estimator="kalman")
    with pytest.raises(ValueError, match="LoopSensors.mag_period_s: expected a whole multiple"):
        LoopSensors(mag_period_s=0.021)


def test_thrust_attitude_tilts_toward_the_acceleration_and_holds_the_weight():
    from quadlib.geometry import quat_to_euler

    q, thrust_z = thrust_attitude(np.array([2.0, 0.0, 0.0]), 0.0, 1.1)
    roll, pitch, yaw = quat_to_euler(q)
    assert pitch == pytest.approx(-np.arctan2(2.0, 9.80665), abs=1e-12) and abs(roll) < 1e-12  # nose down
    assert thrust_z == pytest.approx(1.1 * 9.80665)
    q_east, _ = thrust_attitude(np.zeros(3), np.pi / 2, 1.1)
    assert quat_to_euler(q_east)[2] == pytest.approx(np.pi / 2)


def test_the_square_flown_closed_loop_on_the_truth_and_on_the_ins():
    from quadlib.quad.flight import square_course

    square = square_course(leg_s=4.0, turn_s=2.0)
    truth = fly_path(square)
    tracking = np.sqrt(np.mean(np.sum((truth.state[:, :3] - truth.pos_ref) ** 2, axis=1)))
    assert tracking < 0.1  # measured 4 cm
    ins = fly_path(square, estimator="ins", rng=np.random.default_rng(0))
    estimate = np.sqrt(np.mean(np.sum((ins.pos_est - ins.state[:, :3]) ** 2, axis=1)))
    tracking_ins = np.sqrt(np.mean(np.sum((ins.state[:, :3] - ins.pos_ref) ** 2, axis=1)))
    assert estimate < 0.5 and tracking < tracking_ins < 1.0  # the estimate's error becomes tracking error


def test_the_2d_quadrotor_holds_half_a_metre_from_the_wall_on_its_own_estimate():
    from quadlib import ModelUKF
    from quadlib.control import hold_distance
    from quadlib.quad import quad2d_model, quad2d_range_sensor

    wall, dt = 5.0, 0.05
    t = np.arange(0.0, 6.0 + dt / 2, dt)
    model, sensor = quad2d_model(0.2, np.radians(3.0)), quad2d_range_sensor(0.01, wall_y_m=wall)
    rng = np.random.default_rng(0)
    P0 = np.diag([np.radians(3.0) ** 2, 0.05**2, 0.1**2])
    runs = [hold_distance(model, sensor, ModelUKF(model, [0.0, 0.0, wall - 2.0], P0, dt), t,
                          [0.0, 0.0, wall - 2.0 + 0.1 * rng.standard_normal()], wall - 0.5, rng, sample_every=2)
            for _ in range(10)]
    closest = np.array([(wall - r.truth[:, 2]).min() for r in runs])
    assert np.all(closest > 0.2) and np.median(closest) < 0.6  # within about half a metre, never touching
    last = np.array([wall - r.truth[-20:, 2].mean() for r in runs])
    assert np.all(np.abs(last - 0.5) < 0.2)
