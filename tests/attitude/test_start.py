"""Where the orientation filter starts: any magnetometer schedule, any mounting, any declination."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.analysis import attitude_error, broad_errors
from quadlib.attitude import OrientationParams, SensorChecks, orientation_run
from quadlib.data import load_broad_trial
from quadlib.geometry import quat_multiply

TRIAL = load_broad_trial("02_undisturbed_slow_rotation_B")
LOG = TRIAL.log.slice(0, 30_000)
TRUTH, MOVING = TRIAL.q_nb[:30_000], TRIAL.movement[:30_000]
BASE = orientation_run(LOG).x[:, :4]


def _turn(angle):
    return np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])


@pytest.mark.parametrize("declination_deg", [40.0, 120.0, -170.0])
def test_any_declination_turns_the_whole_estimate_about_down(declination_deg):
    d = np.radians(declination_deg)
    q = orientation_run(LOG, declination_rad=d).x[:, :4]
    assert np.degrees(attitude_error(q, quat_multiply(_turn(d), BASE))).max() < 1e-6


def _inclination_after(q, truth, seconds):
    later = LOG.t >= seconds
    return broad_errors(q[later], truth[later], MOVING[later])["inclination_deg"]


@pytest.mark.parametrize("mag", ["none", "all NaN", "along gravity"])
def test_without_a_usable_magnetometer_the_tilt_starts_from_the_accelerometer(mag):
    field = {"none": None, "all NaN": np.full_like(LOG.mag, np.nan),
             "along gravity": LOG.accel * 3.0}[mag]
    q = orientation_run(replace(LOG, mag=field)).x[:, :4]
    assert np.isfinite(q).all()
    assert _inclination_after(q, TRUTH, 5.0) < 1.0


def test_upside_down_without_a_magnetometer_converges_within_5_s():
    flip = np.diag([1.0, -1.0, -1.0])  # the sensor mounted turned 180° about its x axis
    log = replace(LOG, gyro=LOG.gyro @ flip.T, accel=LOG.accel @ flip.T, mag=None)
    truth = quat_multiply(np.nan_to_num(TRUTH), np.array([0.0, -1.0, 0.0, 0.0]))
    truth[np.isnan(TRUTH).any(axis=1)] = np.nan
    run = orientation_run(log)
    assert _inclination_after(run.x[:, :4], truth, 5.0) < 1.0
    assert np.abs(run.x[-1, 4:]).max() < np.radians(1.0)  # no false gyro bias learnt


def test_a_late_first_magnetometer_reading_starts_the_heading_there():
    mag = LOG.mag.copy()
    mag[:2_000] = np.nan  # seven seconds without the field
    q = orientation_run(replace(LOG, mag=mag)).x[:, :4]
    later = LOG.t >= 30.0
    assert np.degrees(attitude_error(q[later], BASE[later])).max() < 0.5


SLIDING = load_broad_trial("10_undisturbed_slow_translation_A")  # the board carried about, mostly moving


def _heading_after(run, later):
    return broad_errors(run.x[later, :4], SLIDING.q_nb[later], SLIDING.movement[later])["heading_deg"]


def test_a_first_magnetometer_reading_during_motion_is_checked_against_the_same_down():
    """The field's first reading at 66.46 s, mid-translation: its dip is measured against the same
    low-passed down as every later reading's (not the raw accelerometer's, 20° off there), so the
    readings after it are used and the heading holds (against every one refused and 40° before). The
    field's strength is checked at SensorChecks' 20 %, so that only the dip decides: at the default 5 %,
    the 8 % stronger field where this trial carries the board is refused for its strength."""
    log = SLIDING.log
    run = orientation_run(replace(log, mag=np.where((log.t < 66.46)[:, None], np.nan, log.mag)),
                          OrientationParams(checks=SensorChecks()))
    assert run.sensors["heading"].used[log.t > 66.46].mean() > 0.95
    assert _heading_after(run, log.t > 96.46) < 3.0


def test_a_field_disturbed_at_the_start_gives_way_to_the_earths_once_the_sensor_turns():
    """A magnet beside the sensor for its first 3 s makes the first reading's field 50 % too
    strong: without the replacement, every reading after it is refused (1.6 % used; the gyro, its
    bias held from the rests, still keeps the heading within 1.3° RMS on this trial); with it, the
    field that holds for 20 s of turning is taken (38 % used). With the first reading's field on
    trial for its first 5 s of trust (``mag_first_field_s``, the default), the Earth's field, steady
    from 3 s, replaces it at 8 s (all used after 9 s, 2.0°). The field's strength is checked at
    SensorChecks' 20 %, so that the field where this trial carries the board (8 % stronger) counts."""
    log = SLIDING.log
    log = replace(log, mag=np.where((log.t < 3.0)[:, None], 1.5, 1.0) * log.mag)
    loose = SensorChecks()
    kept, replaced = (orientation_run(log, OrientationParams(mag_new_field_s=s, mag_first_field_s=None, checks=loose))
                      for s in (None, 20.0))
    assert kept.sensors["heading"].used.mean() < 0.05
    assert replaced.sensors["heading"].used.mean() > 0.3 and _heading_after(replaced, log.t >= 0.0) < 3.0
    waited = orientation_run(log, OrientationParams(mag_first_field_s=5.0, checks=loose))
    used = waited.sensors["heading"].used
    assert not used[(log.t > 3.1) & (log.t < 7.9)].any() and used[log.t > 9.0].mean() > 0.9
    assert _heading_after(waited, log.t >= 0.0) < 3.0


def test_a_first_magnetometer_reading_while_the_sensor_turns_gives_the_heading_of_the_first_sample():
    """Trial 16's board moves from 35 s on; with the field's first reading at 45.8 s, the start's
    heading is that reading turned back through the gyro to the first sample, not the reading's
    own (126° off at the start, and every heading after it refused)."""
    shaken = load_broad_trial("16_undisturbed_fast_translation_B")
    log = shaken.log
    run = orientation_run(replace(log, mag=np.where((log.t < 45.8)[:, None], np.nan, log.mag)))
    later = (log.t > 55.8) & shaken.movement
    assert run.sensors["heading"].used[log.t > 45.8].mean() > 0.95
    assert broad_errors(run.x[later, :4], shaken.q_nb[later])["heading_deg"] < 1.5
