"""The tilt read from the averaged gravity: how far it moves the filter's, and where it does not."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.analysis.metrics import broad_errors
from quadlib.attitude.orientation import OrientationParams, estimate_orientation
from quadlib.attitude.tilt import refined_tilt
from quadlib.data import load_broad_trial
from quadlib.geometry.quaternion import (
    quat_conjugate,
    quat_from_euler,
    quat_from_rotvec,
    quat_multiply,
    quat_to_dcm,
    quat_to_euler,
)

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
    np.testing.assert_allclose(out[:, 2], 0.7, atol=1e-12)  # rolled about the yaw's own x: the yaw kept exactly
    assert np.all(gaps - out[:, 0] <= width / 4 + 1e-15)


def test_any_attitude_is_turned_in_the_earth_frame_about_a_horizontal_axis_toward_the_average():
    """Random attitudes and averages off the body axes: the turn ``out ⊗ q*`` has no vertical part,
    its angle is γ·max(0, 1 − γ/w), and the gap left is γ minus it."""
    rng = np.random.default_rng(3)
    q = quat_from_rotvec(rng.normal(size=(500, 3)))
    f_true = np.einsum("nji,j->ni", quat_to_dcm(q), [0.0, 0.0, -G])  # the body's specific force if q were right
    f = np.einsum("nij,nj->ni", quat_to_dcm(quat_from_rotvec(rng.normal(scale=0.05, size=(500, 3)))), f_true)
    width = np.radians(4.0)

    def gap(attitude):
        down = np.einsum("nij,nj->ni", quat_to_dcm(attitude), -f / np.linalg.norm(f, axis=1, keepdims=True))
        return np.arctan2(np.hypot(down[:, 0], down[:, 1]), down[:, 2])

    out = refined_tilt(q, f, width)
    turn = quat_multiply(out, quat_conjugate(q))
    turn *= np.sign(turn[:, :1])
    before = gap(q)
    np.testing.assert_allclose(turn[:, 3], 0.0, atol=1e-12)  # about a horizontal axis
    np.testing.assert_allclose(2 * np.arccos(np.clip(turn[:, 0], -1, 1)),
                               before * np.clip(1 - before / width, 0, 1), atol=1e-7)
    np.testing.assert_allclose(gap(out), before - before * np.clip(1 - before / width, 0, 1), atol=1e-7)
    assert (before > width).any() and (before < width / 2).any()  # both sides of the width are tried


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


def test_offline_the_smoothed_tilt_is_refined_with_the_two_sided_average():
    """Offline the refinement uses the two-sided average and the smoothed bias: on trial 30 it lowers
    the smoother's inclination error too, and leaves its heading within 0.01°."""
    trial = load_broad_trial("30_disturbed_stationary_magnet_C")
    plain = replace(OrientationParams(), tilt_refinement_deg=None)
    refined = broad_errors(estimate_orientation(trial.log, offline=True).q, trial.q_nb, trial.movement)
    own = broad_errors(estimate_orientation(trial.log, params=plain, offline=True).q, trial.q_nb, trial.movement)
    assert refined["inclination_deg"] < own["inclination_deg"] - 0.02
    assert refined["heading_deg"] == pytest.approx(own["heading_deg"], abs=0.01)


def test_the_butterworth_is_vqfs():
    from vqf import PyVQF

    from quadlib.kernels.lowpass import butterworth

    for tau, dt in ((3.0, 1 / 286.0), (0.5, 0.01), (10.0, 0.001)):
        b, a = PyVQF.filterCoeffs(tau, dt)
        b0, a1, a2 = butterworth(tau, dt)
        np.testing.assert_allclose([b0, 2 * b0, b0, a1, a2], [*b, *a], rtol=1e-12)
