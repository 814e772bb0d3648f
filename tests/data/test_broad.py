"""BROAD loader: the ENU→NED conversion checked against physics, and the benchmark's metric."""

import numpy as np
import pytest

from quadlib.analysis.metrics import broad_errors
from quadlib.data import (
    BroadTrial,
    DataCorruptError,
    DataNotFoundError,
    broad_trial_names,
    gyro_truth_mismatch_deg,
    load_broad_trial,
)
from quadlib.geometry import quat_from_rotvec, quat_multiply, quat_to_dcm
from quadlib.imu import ImuLog

TRIAL = load_broad_trial("02_undisturbed_slow_rotation_B")


def test_the_ten_trials_are_shipped_and_load():
    names = broad_trial_names()
    assert len(names) == 10 and {"09_undisturbed_fast_rotation_with_breaks_B", "34_disturbed_attached_magnet_3cm",
                                 "32_disturbed_attached_magnet_1cm"} <= set(names)
    assert TRIAL.log.t.size == TRIAL.q_nb.shape[0] == TRIAL.movement.size == 53240
    assert 1 / np.median(TRIAL.log.dt) == pytest.approx(285.714, abs=1e-3)
    assert "undisturbed" in TRIAL.info["groups"]


def test_the_truth_rotates_gravity_and_the_field_into_ned():
    rest = ~TRIAL.movement & ~np.isnan(TRIAL.q_nb[:, 0])
    R = quat_to_dcm(TRIAL.q_nb[rest])
    f_n = np.einsum("nij,nj->ni", R, TRIAL.log.accel[rest]).mean(axis=0)
    np.testing.assert_allclose(f_n, [0.0, 0.0, -9.81], atol=0.1)  # at rest: −g_n, up
    m_n = np.einsum("nij,nj->ni", R, TRIAL.log.mag[rest]).mean(axis=0)
    assert abs(m_n[1]) < 1.0 and m_n[0] > 10.0  # north, the truth's earth frame is magnetic north
    assert 60.0 < np.degrees(np.arctan2(m_n[2], np.hypot(m_n[0], m_n[1]))) < 75.0  # Berlin's dip, downwards
    present = ~np.isnan(TRIAL.q_nb[:, 0])
    assert np.abs(np.linalg.norm(TRIAL.q_nb[present], axis=1) - 1).max() < 1e-6


def test_each_gyro_row_holds_over_the_interval_after_its_time():
    """The loader moves BROAD's gyro one row earlier (its sample at t[k] is the rate before t[k]);
    the optical truth's turns then match the gyro's over each interval, the unmoved rows lag."""
    fast = load_broad_trial("07_undisturbed_fast_rotation_B")
    as_loaded, as_in_file = gyro_truth_mismatch_deg(fast), gyro_truth_mismatch_deg(fast, shift=-1)
    assert as_loaded < 0.5 * as_in_file
    assert np.isnan(fast.log.gyro[-1]).all() and not np.isnan(fast.log.gyro[:-1]).any()
    with pytest.raises(TypeError, match="trial: expected a BroadTrial, got ImuLog"):
        gyro_truth_mismatch_deg(fast.log)


def test_the_timing_mismatch_of_a_known_lag():
    """A truth built from the gyro itself (one constant turn rate) matches at shift 0 exactly and
    is off by one sample's turn per ten samples at shift ±1."""
    n, dt, rate = 400, 0.01, np.array([0.0, 0.0, 1.0])
    t = np.arange(n) * dt
    gyro = np.tile(rate, (n, 1))
    gyro[n // 2:] *= -1.0  # a reversal, so a one-sample shift shows at the turn
    q = np.zeros((n, 4))
    q[0] = [1.0, 0.0, 0.0, 0.0]
    for k in range(n - 1):
        q[k + 1] = quat_multiply(q[k], quat_from_rotvec(gyro[k] * dt))
    trial = BroadTrial("made", ImuLog(t, gyro, gyro, None), q, np.ones(n, bool), np.zeros((n, 3)), {})
    assert gyro_truth_mismatch_deg(trial) == pytest.approx(0.0, abs=1e-9)
    # across the reversal, one sample's turn in the sum has the wrong sign: 2 · 1 rad/s · 0.01 s
    mismatch = gyro_truth_mismatch_deg(trial, shift=1)
    assert mismatch == pytest.approx(np.degrees(2 * dt) * np.sqrt(10 / (n - 10 - 1)), rel=1e-6)


def test_broad_errors_on_a_hand_made_case():
    n = 4
    truth = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    heading = quat_from_rotvec([0.0, 0.0, np.radians(10.0)])  # about the earth's vertical
    tilt = quat_from_rotvec([np.radians(5.0), 0.0, 0.0])
    est = np.array([heading, heading, tilt, tilt])
    errors = broad_errors(est, truth)
    assert errors["heading_deg"] == pytest.approx(np.sqrt((2 * 10**2) / 4))
    assert errors["inclination_deg"] == pytest.approx(np.sqrt((2 * 5**2) / 4))
    assert errors["total_deg"] == pytest.approx(np.sqrt((2 * 10**2 + 2 * 5**2) / 4))
    truth[1] = np.nan  # hidden markers are skipped, still-samples are not counted
    only_moving = broad_errors(-est, truth, movement=np.array([True, True, False, False]))  # the sign does not matter
    assert only_moving == pytest.approx({"total_deg": 10.0, "heading_deg": 10.0, "inclination_deg": 0.0})
    with pytest.raises(ValueError, match="movement: expected a bool array of shape"):
        broad_errors(est, truth, movement=[1, 0, 0, 0])


def test_missing_and_damaged_trials_are_named(monkeypatch, tmp_path):
    with pytest.raises(DataNotFoundError, match="01_undisturbed_slow_rotation_A"):
        load_broad_trial("01_undisturbed_slow_rotation_A")
    bad = tmp_path / "02_undisturbed_slow_rotation_B.hdf5"
    bad.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 64)
    with pytest.raises(DataCorruptError, match="not a readable BROAD trial"):
        load_broad_trial(bad)
    with pytest.raises(TypeError, match="trial: expected a trial name or a path, got int"):
        load_broad_trial(2)
