"""The fixed-wing estimators on run_filter: simulator truth, convergence, bias, sensor failures,
the error-state model's Jacobians, and the one-call entry point."""

import numpy as np
import pytest

from quadlib import ModelEKF, run_filter
from quadlib.analysis.metrics import angle_rmse, attitude_error
from quadlib.fixedwing.estimate import (
    FixedWingParams,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_measurements,
    initial_state,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.fixedwing.model import FixedWingNoise, fixedwing_f, fixedwing_mag_sensor, fixedwing_model
from quadlib.fixedwing.sim import aileron_roll, fixedwing_flight, fixedwing_samples
from quadlib.geometry.quaternion import integrate_body_rate, quat_canonical, quat_to_dcm, quat_to_euler
from quadlib.geometry.rotations import wrap_angle
from quadlib.imu import ImuLog

FLIGHT = fixedwing_flight(rate_hz=50.0)
NOISE = FixedWingNoise()
LOG = fixedwing_samples(FLIGHT, NOISE, np.random.default_rng(12))


def _euler_error_deg(x, flight=FLIGHT):
    n = len(x)
    return np.degrees(np.column_stack([wrap_angle(a - b) for a, b in zip(quat_to_euler(x[:, :4]), flight.euler[:n].T,
                                                                        strict=True)]))


def _run(log=LOG, inclination=NOISE.inclination_rad, factory=salmony_ekf, **kw):
    run = estimate_fixedwing_attitude(log, NOISE, factory, inclination_rad=inclination, **kw)
    return run, _euler_error_deg(run.x)


UNGATED = FixedWingParams(gate_probability=None)  # to compare models: a gate would hide a wrong one's errors


def _run_ungated(log=LOG, inclination=NOISE.inclination_rad):
    run = estimate_fixedwing_attitude(log, NOISE, salmony_ekf, inclination_rad=inclination, params=UNGATED)
    np.testing.assert_array_equal(np.hstack([run.q, run.gyro_bias]), run.x)
    return run, _euler_error_deg(run.x)


def test_simulated_truth_is_consistent():
    R = quat_to_dcm(FLIGHT.q_nb)
    q = FLIGHT.q_nb[0]
    for k in range(FLIGHT.t.size - 1):
        q = integrate_body_rate(q, FLIGHT.omega_b[k], FLIGHT.dt)
    np.testing.assert_allclose(quat_canonical(q), quat_canonical(FLIGHT.q_nb[-1]), atol=1e-8)
    assert np.abs(FLIGHT.f_b[:, 1]).max() < 0.05  # coordinated turns: no sideways force
    level = FLIGHT.t < 7.0
    np.testing.assert_allclose(-np.einsum("nij,nj->ni", R[level], FLIGHT.f_b[level]),
                               np.tile([0, 0, 9.80665], (level.sum(), 1)), atol=1e-6)


def test_ekf_tracks_attitude_and_estimates_the_gyro_bias():
    run, err = _run()
    settled = FLIGHT.t > 5.0
    assert np.sqrt(np.mean(err[settled] ** 2, axis=0)).max() < 3.0  # degrees, roll/pitch/yaw
    final_bias = np.mean(LOG.gyro[-50:] - FLIGHT.omega_b[-50:], axis=0)  # the bias at the end (± 0.7 mrad/s)
    assert np.abs(run.x[-1, 4:] - final_bias).max() < 0.005
    assert np.abs(np.linalg.norm(run.x[:, :4], axis=1) - 1).max() < 1e-12  # renormalised (§8.2)


def test_the_chapter_can_build_the_ekf_by_hand_and_gets_the_same_run():
    x0 = initial_state(LOG, 50)
    ekf = ModelEKF(fixedwing_model(NOISE.gyro_sigma_rad_s, NOISE.gyro_bias_walk_rad_s_sqrt_s), x0,
                   np.diag([0.1**2] * 4 + [0.02**2] * 3), FLIGHT.dt)
    mag = fixedwing_mag_sensor(NOISE.declination_rad, NOISE.mag_sigma, NOISE.inclination_rad)
    measurements = fixedwing_measurements(LOG, NOISE.accel_sigma_m_s2, mag)
    by_hand = run_filter(ekf, LOG.t, LOG.gyro, measurements, gate_probability=0.999, engine="readable")
    np.testing.assert_array_equal(by_hand.x, _run(compiled=False)[0].x)  # the readable path, bit for bit
    ekf = ModelEKF(ekf.model, x0, np.diag([0.1**2] * 4 + [0.02**2] * 3), FLIGHT.dt)
    on_engine = run_filter(ekf, LOG.t, LOG.gyro, measurements, gate_probability=0.999)
    np.testing.assert_array_equal(on_engine.x, _run()[0].x)  # and the engine's, bit for bit


def test_magnetometer_and_airspeed_failures_switch_the_model_per_step():
    mag, airspeed = np.array(LOG.mag), np.array(LOG.airspeed)
    mag_lost = (FLIGHT.t > 30) & (FLIGHT.t < 45)  # through the climb and a turn
    mag[mag_lost] = np.nan
    airspeed[(FLIGHT.t > 10) & (FLIGHT.t < 20)] = np.nan  # pitot lost in the right turn
    failed = ImuLog(LOG.t, LOG.gyro, LOG.accel, mag, airspeed)
    run, err = _run(failed)
    assert np.all(np.isfinite(run.x))
    assert run.sensors["mag"].missing.sum() == mag_lost.sum()
    assert run.sensors["accel (no airspeed)"].used.sum() == np.isnan(airspeed).sum()
    assert run.sigma[mag_lost, 2].max() < run.sigma[(FLIGHT.t > 25) & (FLIGHT.t < 30), 2].max() * 50  # bounded
    _, err_ok = _run()
    late = FLIGHT.t > 60  # ten seconds after both failures ended: back to the unfailed filter's accuracy
    assert np.abs(np.sqrt(np.mean(err[late] ** 2, axis=0)) - np.sqrt(np.mean(err_ok[late] ** 2, axis=0))).max() < 1.0
    # without the switch (airspeed taken as 0 with the normal R), the turn's centripetal force
    # is read as tilt: the roll error in the turn is larger
    zero = ImuLog(LOG.t, LOG.gyro, LOG.accel, LOG.mag, np.where(np.isnan(airspeed), 0.0, airspeed))
    _, err_zero = _run_ungated(zero)
    _, err = _run_ungated(failed)
    turn = (FLIGHT.t > 12) & (FLIGHT.t < 18)
    assert np.abs(err_zero[turn, 0]).mean() > 2 * np.abs(err[turn, 0]).mean()


def test_the_documents_horizontal_field_model_fails_with_a_dipping_field():
    _, err = _run_ungated(inclination=0.0)
    assert np.sqrt(np.mean(err[FLIGHT.t > 5] ** 2, axis=0)).max() > 10.0


@pytest.mark.parametrize("factory", [multiplicative_ekf, error_state_ukf])
def test_error_state_filters_track_the_attitude(factory):
    flight = fixedwing_flight(rate_hz=25.0)
    log = fixedwing_samples(flight, NOISE, np.random.default_rng(13)).slice(0, int(25.0 / flight.dt))  # level + turn
    run = estimate_fixedwing_attitude(log, NOISE, factory)
    err = _euler_error_deg(run.x, flight)
    assert np.sqrt(np.mean(err[log.t > 5.0] ** 2, axis=0)).max() < 3.0
    assert np.abs(np.linalg.norm(run.x[:, :4], axis=1) - 1).max() < 1e-12
    assert run.P.shape == (len(log), 6, 6)


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="n_still: expected an int >= 1, got 0"):
        initial_state(LOG, 0)
    with pytest.raises(TypeError, match="log: expected an ImuLog, got tuple"):
        fixedwing_measurements((LOG.t, LOG.gyro), 0.15, fixedwing_mag_sensor(0.0, 0.01))
    with pytest.raises(ValueError, match="log: expected magnetometer and airspeed samples"):
        fixedwing_measurements(ImuLog(LOG.t, LOG.gyro, LOG.accel), 0.15, fixedwing_mag_sensor(0.0, 0.01))
    with pytest.raises(ValueError, match="gyro_sigma_rad_s: expected a finite number > 0"):
        fixedwing_model(0.0, 1e-4)
    with pytest.raises(ValueError, match="n_still"):
        estimate_fixedwing_attitude(LOG, NOISE, params=FixedWingParams(n_still=-3))


def test_the_seed_that_diverged_no_longer_does_and_spikes_are_gated():
    """Seed 10 at 50 Hz drove the EKF to 180° in 3 s while the quaternion's radial variance stayed in P;
    carrying P through the renormalisation, and the gate, keep every seed and spike under a few degrees."""
    flight = fixedwing_flight(rate_hz=50.0)
    log = fixedwing_samples(flight, NOISE, np.random.default_rng([12, 10]))
    accel = np.array(log.accel)
    spikes = np.random.default_rng(99).random(len(accel)) < 0.02
    accel[spikes] += np.random.default_rng(98).normal(0.0, 20 * NOISE.accel_sigma_m_s2, (spikes.sum(), 3))
    late = flight.t > 5.0
    for current in (log, ImuLog(log.t, log.gyro, accel, log.mag, log.airspeed)):
        run = estimate_fixedwing_attitude(current, NOISE)
        assert np.degrees(attitude_error(run.x[:, :4], flight.q_nb))[late].max() < 5.0
        roll_pitch = np.column_stack(quat_to_euler(run.x[:, :4]))[:, :2]
        assert np.degrees(angle_rmse(roll_pitch[late], flight.euler[late, :2], axis=None)) < 2.0
    assert run.sensors["accel"].rejected[spikes].mean() > 0.9  # the spikes were gated out


def test_the_covariance_follows_the_renormalisation():
    model = fixedwing_model(0.005, 1e-4)
    x = np.r_[1.2 * quat_canonical(np.array([0.9, 0.1, -0.3, 0.3])), 0.01, 0.0, 0.0]
    eps = 1e-7
    fd = np.column_stack([(model.normalize(x + eps * e) - model.normalize(x - eps * e)) / (2 * eps) for e in np.eye(7)])
    np.testing.assert_allclose(model.normalize_jacobian(x), fd, atol=1e-7)
    q_hat = model.normalize(x)[:4]
    assert np.abs(model.normalize_jacobian(x)[:4, :4] @ q_hat).max() < 1e-12  # no variance along the normal


def test_dropouts_in_the_initialisation_window_are_averaged_over():
    mag = np.array(LOG.mag)
    mag[[3, 17, 30]] = np.nan
    x0 = initial_state(ImuLog(LOG.t, LOG.gyro, LOG.accel, mag, LOG.airspeed), 50)
    assert np.degrees(attitude_error(x0[:4], initial_state(LOG, 50)[:4])) < 0.5  # as without the dropouts
    mag[:50] = np.nan
    with pytest.raises(ValueError, match="magnetometer samples among the first 50, got 50, 50 and 0"):
        initial_state(ImuLog(LOG.t, LOG.gyro, LOG.accel, mag, LOG.airspeed), 50)


def test_the_prefilter_holds_its_state_over_magnetometer_dropouts():
    from quadlib.fixedwing.model import lowpass2

    x = np.ones((10, 3))
    x[4:6] = np.nan
    y = lowpass2(x, 2.0, 0.02)
    assert np.isnan(y[4:6]).all() and np.allclose(y[~np.isnan(x[:, 0])], 1.0)  # a constant passes, gaps stay gaps
    mag = np.array(LOG.mag)
    mag[np.random.default_rng(3).random(len(mag)) < 0.3] = np.nan
    with_gaps = ImuLog(LOG.t, LOG.gyro, LOG.accel, mag, LOG.airspeed)
    _, err = _run(with_gaps, prefilter_hz=2.0)
    assert np.sqrt(np.mean(err[FLIGHT.t > 5] ** 2, axis=0)).max() < 3.0  # degrees; zeros in the gaps gave ~80


def test_fast_rolls_are_integrated_exactly():
    """Three rolls at 42 rad/s (0.84 rad per 50 Hz step): the exact gyro step keeps the EKF within a
    degree; the document’s Euler step, renormalised, loses 18° per roll in pure integration."""
    flight = aileron_roll(FLIGHT, 62.0, 42.0, turns=3)
    assert np.degrees(attitude_error(flight.q_nb[-1], FLIGHT.q_nb[-1])) < 1e-6  # three whole turns
    run = estimate_fixedwing_attitude(fixedwing_samples(flight, NOISE, np.random.default_rng(12)), NOISE)
    assert np.degrees(attitude_error(run.x[flight.t >= 62.0, :4], flight.q_nb[flight.t >= 62.0])).max() < 2.0
    x = np.r_[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    steps = int(round(2 * np.pi / 42.0 / FLIGHT.dt))
    euler = x.copy()
    for _ in range(steps):
        euler = euler + FLIGHT.dt * fixedwing_f(euler, [42.0, 0.0, 0.0])
        euler[:4] /= np.linalg.norm(euler[:4])
    exact = fixedwing_model(0.005, 1e-4).g
    for _ in range(steps):
        x = exact(x, np.array([42.0, 0.0, 0.0]), FLIGHT.dt)
    turned = 42.0 * FLIGHT.dt * steps
    truth = np.r_[np.cos(turned / 2), np.sin(turned / 2), 0.0, 0.0]
    assert np.degrees(attitude_error(x[:4], truth)) < 1e-9
    assert np.degrees(attitude_error(euler[:4], truth)) > 10.0
