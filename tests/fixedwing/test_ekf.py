"""Salmony's fixed-wing EKF: simulator truth, convergence, bias estimate, sensor failures."""

import numpy as np
import pytest

from quadlib import ModelEKF
from quadlib.fixedwing.ekf import fixedwing_mag_sensor, fixedwing_model, initial_state, run_fixedwing_ekf
from quadlib.fixedwing.sim import FixedWingNoise, FixedWingSamples, fixedwing_flight, fixedwing_samples
from quadlib.geometry.quaternion import integrate_body_rate, quat_canonical, quat_to_dcm, quat_to_euler
from quadlib.geometry.rotations import wrap_angle

FLIGHT = fixedwing_flight(rate_hz=50.0)
NOISE = FixedWingNoise()
SAMPLES = fixedwing_samples(FLIGHT, NOISE, np.random.default_rng(12))
MODEL = fixedwing_model(NOISE.gyro_sigma_rad_s, 1e-4)
P0 = np.diag([0.01] * 4 + [0.02**2] * 3)


def _run(samples=SAMPLES, inclination=NOISE.inclination_rad, **kw):
    mag = fixedwing_mag_sensor(NOISE.declination_rad, 0.01, inclination)
    x, sigma = run_fixedwing_ekf(ModelEKF(MODEL, initial_state(samples, 100), P0, FLIGHT.dt), FLIGHT.dt, samples,
                                 mag, NOISE.accel_sigma_m_s2, **kw)
    err = np.degrees(np.column_stack([wrap_angle(a - b) for a, b in zip(quat_to_euler(x[:, :4]), FLIGHT.euler.T,
                                                                        strict=True)]))
    return x, sigma, err


def test_simulated_truth_is_consistent():
    R = quat_to_dcm(FLIGHT.q_nb)
    q = FLIGHT.q_nb[0]
    for k in range(FLIGHT.t.size - 1):
        q = integrate_body_rate(q, FLIGHT.omega_b[k], FLIGHT.dt)
    np.testing.assert_allclose(quat_canonical(q), quat_canonical(FLIGHT.q_nb[-1]), atol=1e-8)
    assert np.abs(FLIGHT.f_b[:, 1]).max() < 0.05  # coordinated turns: no sideways force
    level = FLIGHT.t < 7.0
    np.testing.assert_allclose(-np.einsum("nij,nj->ni", R[level], FLIGHT.f_b[level]), np.tile([0, 0, 9.80665],
                                                                                              (level.sum(), 1)),
                               atol=1e-6)


def test_ekf_tracks_attitude_and_estimates_the_gyro_bias():
    x, sigma, err = _run()
    settled = FLIGHT.t > 5.0
    assert np.sqrt(np.mean(err[settled] ** 2, axis=0)).max() < 3.0  # degrees, roll/pitch/yaw
    final_bias = np.mean(SAMPLES.gyro[-50:] - FLIGHT.omega_b[-50:], axis=0)  # the bias at the end (± 0.7 mrad/s)
    assert np.abs(x[-1, 4:] - final_bias).max() < 0.005
    assert np.abs(np.linalg.norm(x[:, :4], axis=1) - 1).max() < 1e-12  # renormalised (§8.2)


def test_magnetometer_and_airspeed_failures_switch_the_model_per_step():
    mag = SAMPLES.mag.copy()
    airspeed = SAMPLES.airspeed.copy()
    mag[(FLIGHT.t > 30) & (FLIGHT.t < 45)] = np.nan  # magnetometer lost through the climb and a turn
    airspeed[(FLIGHT.t > 10) & (FLIGHT.t < 20)] = np.nan  # pitot lost in the right turn
    failed = FixedWingSamples(SAMPLES.gyro, SAMPLES.accel, mag, airspeed)
    x, sigma, err = _run(failed)
    assert np.all(np.isfinite(x))
    during_mag = (FLIGHT.t > 30) & (FLIGHT.t < 45)
    assert sigma[during_mag, 0].max() < sigma[(FLIGHT.t > 25) & (FLIGHT.t < 30), 0].max() * 50  # bounded
    _, _, err_ok = _run()
    late = FLIGHT.t > 60  # ten seconds after both failures ended: back to the unfailed filter's accuracy
    assert np.abs(np.sqrt(np.mean(err[late] ** 2, axis=0)) - np.sqrt(np.mean(err_ok[late] ** 2, axis=0))).max() < 1.0
    # without the switch (airspeed taken as 0 with the normal R), the turn's centripetal force
    # is read as tilt: the roll error in the turn is larger
    zero = FixedWingSamples(SAMPLES.gyro, SAMPLES.accel, SAMPLES.mag, np.where(np.isnan(airspeed), 0.0, airspeed))
    _, _, err_zero = _run(zero)
    turn = (FLIGHT.t > 12) & (FLIGHT.t < 18)
    assert np.abs(err_zero[turn, 0]).mean() > 2 * np.abs(err[turn, 0]).mean()


def test_the_documents_horizontal_field_model_fails_with_a_dipping_field():
    _, _, err = _run(inclination=0.0)
    assert np.sqrt(np.mean(err[FLIGHT.t > 5] ** 2, axis=0)).max() > 10.0


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="n_still: expected an int >= 1, got 0"):
        initial_state(SAMPLES, 0)
    ekf = ModelEKF(MODEL, initial_state(SAMPLES, 10), P0, FLIGHT.dt)
    mag = fixedwing_mag_sensor(NOISE.declination_rad, 0.01)
    short = FixedWingSamples(SAMPLES.gyro, SAMPLES.accel[:-1], SAMPLES.mag, SAMPLES.airspeed)
    with pytest.raises(ValueError, match=r"samples: expected gyro, accel, mag of shape \(N, 3\)"):
        run_fixedwing_ekf(ekf, FLIGHT.dt, short, mag, 0.15)
    with pytest.raises(TypeError, match="samples: expected FixedWingSamples, got tuple"):
        run_fixedwing_ekf(ekf, FLIGHT.dt, tuple(SAMPLES), mag, 0.15)
    with pytest.raises(ValueError, match="dt"):
        run_fixedwing_ekf(ekf, -0.1, SAMPLES, mag, 0.15)


def test_error_state_ukf_tracks_the_attitude_with_plain_vector_means():
    from quadlib.fixedwing.ukf import ErrorStateUKF

    flight = fixedwing_flight(rate_hz=25.0)
    samples = fixedwing_samples(flight, NOISE, np.random.default_rng(13))
    n = int(25.0 / flight.dt)  # the first 25 s: level flight and the right turn
    x0 = initial_state(samples, 50)
    ukf = ErrorStateUKF(x0[:4], x0[4:], 0.05, 0.02, NOISE.gyro_sigma_rad_s, 1e-4, flight.dt)
    states = np.empty((n, 7))
    for k in range(n):
        if k:
            ukf.predict(samples.gyro[k - 1], flight.dt)
        ukf.update(samples.accel[k], samples.mag[k], omega=samples.gyro[k], airspeed_m_s=samples.airspeed[k],
                   accel_sigma=NOISE.accel_sigma_m_s2, mag_sigma=0.01, declination_rad=NOISE.declination_rad,
                   inclination_rad=NOISE.inclination_rad)
        states[k] = ukf.state
        assert np.allclose(ukf.ukf.estimate[:3], 0.0)  # the mean rotation is folded into q_ref every step
    err = np.degrees(np.column_stack([wrap_angle(a - b) for a, b in zip(quat_to_euler(states[:, :4]),
                                                                        flight.euler[:n].T, strict=True)]))
    assert np.sqrt(np.mean(err[flight.t[:n] > 5.0] ** 2, axis=0)).max() < 3.0
    assert np.abs(np.linalg.norm(states[:, :4], axis=1) - 1).max() < 1e-12
