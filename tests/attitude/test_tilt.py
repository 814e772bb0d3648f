"""The tilt read from the averaged gravity: how far it moves the filter's, and where it does not."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.analysis.metrics import broad_errors
from quadlib.attitude.orientation import OrientationParams, estimate_orientation
from quadlib.attitude.tilt import refined_tilt
from quadlib.data import load_broad_trial
from quadlib.geometry.quaternion import quat_from_euler, quat_to_euler

G = 9.80665


def _tilted(roll_rad, yaw_rad=0.7):
    return quat_from_euler(roll_rad, np.zeros_like(roll_rad), np.full_like(roll_rad, yaw_rad))


def test_the_gap_is_closed_by_gamma_times_one_minus_gamma_over_width():
    """The average says level; the filter's attitude is rolled by γ: the result is rolled by
    γ²/w (γ − γ(1 − γ/w)), never moved by more than w/4, left alone from w on, its heading kept."""
    width = np.radians(4.0)
    gaps = np.radians([0.0, 0.5, 1.0, 2.0, 3.9, 4.0, 10.0])
    level = np.tile([0.0, 0.0, -G], (len(gaps), 1))  # a level body's specific force, whatever its heading
    out = np.column_stack(quat_to_euler(refined_tilt(_tilted(gaps), level, width)))
    expected = np.where(gaps < width, gaps**2 / width, gaps)
    np.testing.assert_allclose(out[:, 0], expected, atol=1e-12)
    np.testing.assert_allclose(out[:, 2], 0.7, atol=1e-12)  # turned about a horizontal axis: the yaw kept
    assert np.all(gaps - expected <= width / 4 + 1e-15)


def test_it_moves_the_attitude_continuously_and_leaves_missing_rows_alone():
    gaps = np.radians(np.linspace(0, 8, 801))  # 0.01° apart, through the width
    level = np.tile([0.0, 0.0, -G], (len(gaps), 1))
    roll = np.degrees(quat_to_euler(refined_tilt(_tilted(gaps), level, np.radians(4.0)))[0])
    assert np.abs(np.diff(roll)).max() < 0.0201  # at most twice the gap's step (d(γ²/w)/dγ = 2γ/w): no jump
    level[100] = np.nan
    q = _tilted(gaps)
    assert np.array_equal(refined_tilt(q, level, np.radians(4.0))[100], q[100])


def test_bad_arguments_are_named():
    q = _tilted(np.zeros(3))
    with pytest.raises(ValueError, match="specific_force_b: expected shape"):
        refined_tilt(q, np.zeros((2, 3)), 0.1)
    with pytest.raises(ValueError, match="width_rad"):
        refined_tilt(q, np.ones((3, 3)), 0.0)


def test_on_a_real_trial_it_lowers_the_inclination_error_and_keeps_the_heading():
    """BROAD's trial 30, fast turns beside a magnet: online, the refined tilt's inclination error is
    lower than the filter's own, and the heading error the same to 0.01°."""
    trial = load_broad_trial("30_disturbed_stationary_magnet_C")
    refined = broad_errors(estimate_orientation(trial.log).q, trial.q_nb, trial.movement)
    own = broad_errors(estimate_orientation(trial.log, params=replace(OrientationParams(), tilt_refinement_deg=None)).q,
                       trial.q_nb, trial.movement)
    assert refined["inclination_deg"] < own["inclination_deg"] - 0.1
    assert refined["heading_deg"] == pytest.approx(own["heading_deg"], abs=0.01)
