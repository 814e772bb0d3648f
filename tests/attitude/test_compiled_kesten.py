"""Kesten's five filters compiled give what the readable ones (ModelEKF driven by run_filter) give:
the same states, covariances and sensor traces, to 1e-10 — with dropouts, held gyro rows, samples
the plausibility checks drop, a saturated gyro, a tumble through 180° and the thesis's noise."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.attitude.kesten import FILTERS, AttitudeNoise, KestenFilter, run_attitude_filter
from quadlib.attitude.tumble import random_rotation, with_spin
from quadlib.imu import ImuLog
from quadlib.sim.imu import imu_samples

NOISE = AttitudeNoise()


def _log():
    """4 s of a fast tumble at 250 Hz with a roll of one turn, the gyro clipped at 0.8 of its largest rate, 5 % of every
    stream missing, a magnet for half a second and free fall for a tenth."""
    motion = with_spin(random_rotation(4.0, 250.0, np.random.default_rng(11), rms_rate_rad_s=2.0), 2.5, 0.5, 12.0)
    log = imu_samples(motion, NOISE, np.random.default_rng(12), field_n=NOISE.field_n)
    rng = np.random.default_rng(13)
    gyro, accel, mag = log.gyro.copy(), log.accel.copy(), log.mag.copy()
    for stream in (gyro, accel, mag):
        stream[rng.random(len(log)) < 0.05] = np.nan
    gyro[0] = log.gyro[0]
    mag[(log.t > 1.0) & (log.t < 1.5)] *= 3.0  # a magnet: the norm check drops these
    accel[(log.t > 2.0) & (log.t < 2.1)] = 0.0  # free fall
    gyro_range = 0.8 * float(np.nanmax(np.abs(gyro)))
    return ImuLog(log.t, np.clip(gyro, -gyro_range, gyro_range), accel, mag), gyro_range


LOG, GYRO_RANGE = _log()
NOISES = {"corrected noise, saturating gyro": replace(NOISE, gyro_range_rad_s=GYRO_RANGE),
          "thesis's noise": replace(NOISE, thesis_process_noise=True)}


@pytest.mark.parametrize("noise", list(NOISES))
@pytest.mark.parametrize("name", list(FILTERS))
def test_the_compiled_loop_equals_the_readable_one(name, noise, assert_same_run):
    filt = FILTERS[name](NOISES[noise], sigma0_rad=0.5)
    q0 = [0.9, 0.1, -0.3, 0.2]
    compiled, readable = run_attitude_filter(filt, LOG, q0), run_attitude_filter(filt, LOG, q0, compiled=False)
    assert_same_run(compiled.run, readable.run)
    np.testing.assert_allclose(compiled.q_nb, readable.q_nb, rtol=0, atol=1e-10)


def test_the_log_reaches_every_branch():
    run = run_attitude_filter(FILTERS["QF"](NOISES["corrected noise, saturating gyro"]), LOG).run
    assert run.held_input.sum() > 20
    assert run.sensors["mag"].missing.sum() > 150 and run.sensors["accel"].missing.sum() > 60  # the magnet, free fall
    assert (np.abs(LOG.gyro) >= 0.999 * GYRO_RANGE).any(axis=1).sum() > 20  # saturated steps
    theta = run_attitude_filter(FILTERS["TOVKF"](NOISE), LOG).run.x
    assert np.linalg.norm(theta, axis=1).max() > 3.0  # the orientation vector passes near π


def test_a_hand_built_filter_or_a_repeated_time_takes_the_readable_loop(assert_same_run):
    """Only the five factories' filters have a compiled twin; a clock that repeats a time goes to
    run_filter, which drops the repeated samples."""
    tqf = FILTERS["TQF"](NOISE)
    hand_built = KestenFilter(*tqf[:-1])  # the same parts, no noise: the compiled loop cannot know them
    assert hand_built.noise is None
    assert_same_run(run_attitude_filter(hand_built, LOG).run, run_attitude_filter(tqf, LOG, compiled=False).run)
    t = LOG.t.copy()
    t[300] = t[299] + 1e-12
    repeated = ImuLog(t, LOG.gyro, LOG.accel, LOG.mag)
    run = run_attitude_filter(tqf, repeated).run
    assert run.sensors["attitude"].duplicate[300]
    assert_same_run(run, run_attitude_filter(tqf, repeated, compiled=False).run)


def test_the_tumble_is_integrate_body_rate_bit_for_bit():
    """random_rotation integrates with the one-quaternion kernels; every stored Fig. 5.2 number
    depends on its truth being eq. (2.7) exactly as integrate_body_rate computes it."""
    from quadlib.geometry.quaternion import integrate_body_rate

    motion = random_rotation(2.0, 250.0, np.random.default_rng(10))
    q = motion.q_nb[:1].copy()
    for k in range(1, motion.t.size):
        q = np.vstack([q, integrate_body_rate(q[-1], motion.omega_b[k - 1], 1.0 / 250.0)])
    np.testing.assert_array_equal(q, motion.q_nb)
