import numpy as np
import pytest
from scipy.stats import chi2

from quadlib.analysis.metrics import chi2_interval, fraction_inside, nees, nis, rmse, settling_time


def test_rmse_per_column_and_nan_skipped():
    err = np.array([[3.0, 1.0], [4.0, np.nan], [0.0, 1.0]])
    np.testing.assert_allclose(rmse(err), [np.sqrt(25 / 3), 1.0])
    assert rmse([3.0, 4.0], axis=None) == pytest.approx(np.sqrt(12.5))
    with pytest.raises(ValueError, match="error: expected finite values"):
        rmse([np.inf])


def test_nees_known_values():
    P = np.array([[4.0, 0.0], [0.0, 1.0]])
    np.testing.assert_allclose(nees([[2.0, 1.0], [0.0, 3.0]], P), [2.0, 9.0])
    with pytest.raises(ValueError, match=r"P: expected shape \(2, 2, 2\) to match error"):
        nees(np.ones((2, 2)), np.eye(3))


def test_nees_is_chi2_distributed_for_correct_covariance():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(3, 3))
    P = A @ A.T + np.eye(3)
    e = rng.multivariate_normal(np.zeros(3), P, size=20000)
    values = nees(e, P)
    assert values.mean() == pytest.approx(3.0, abs=0.1)  # sd of the mean is 0.017
    assert fraction_inside(values, (chi2.ppf(0.025, 3), chi2.ppf(0.975, 3))) == pytest.approx(0.95, abs=0.01)


def test_nis_skips_missing():
    out = nis([[1.0], [np.nan], [2.0]], np.full((3, 1, 1), 4.0))
    assert out[0] == pytest.approx(0.25) and np.isnan(out[1]) and out[2] == pytest.approx(1.0)


def test_chi2_interval_single_and_monte_carlo():
    low, high = chi2_interval(2, 1, 0.95)
    assert (low, high) == pytest.approx((0.0506356, 7.3777589), rel=1e-6)
    low, high = chi2_interval(2, 100, 0.95)
    assert low == pytest.approx(chi2.ppf(0.025, 200) / 100) and high == pytest.approx(chi2.ppf(0.975, 200) / 100)
    assert 1.6 < low < 2 < high < 2.5  # averaging narrows the interval around dof
    with pytest.raises(ValueError, match="dof: expected an int >= 1, got 0"):
        chi2_interval(0)
    with pytest.raises(ValueError, match="n_runs: expected an int >= 1, got 2.5"):
        chi2_interval(1, 2.5)


def test_settling_time():
    t = np.arange(0, 10, 1.0)
    x = np.array([0, 0, 0, 5, 8, 9.5, 10.2, 9.9, 10, 10])
    assert settling_time(t, x, target=10, tolerance=0.6, t_start=3.0) == pytest.approx(2.0)
    assert settling_time(t, x, target=20, tolerance=0.6, t_start=3.0) == np.inf
    with pytest.raises(ValueError, match="tolerance: expected a finite number > 0"):
        settling_time(t, x, 10, 0.0, 3.0)


def test_angle_and_attitude_errors():
    from quadlib.analysis.metrics import angle_error, angle_rmse, attitude_error, attitude_rmse
    from quadlib.geometry.quaternion import quat_from_euler

    np.testing.assert_allclose(angle_error([np.pi - 0.1, -3.0], [-np.pi + 0.1, 3.0]), [-0.2, 2 * np.pi - 6.0])
    assert angle_rmse([3.1, -3.1], [-3.1, 3.1], axis=None) == pytest.approx(2 * np.pi - 6.2)
    q_true = quat_from_euler(np.array([0.1, 0.2]), np.array([0.0, -0.3]), np.array([3.1, -3.1]))
    q_est = quat_from_euler(np.array([0.1, 0.2]), np.array([0.0, -0.3]), np.array([3.1 + 0.05, -3.1 - 0.02]))
    np.testing.assert_allclose(attitude_error(q_est, q_true), [0.05, 0.02], atol=1e-12)
    np.testing.assert_allclose(attitude_error(-q_est, q_true), [0.05, 0.02], atol=1e-12)  # sign-blind
    assert attitude_rmse(q_est, q_true) == pytest.approx(np.sqrt((0.05**2 + 0.02**2) / 2))
    with pytest.raises(ValueError, match=r"estimate, truth: expected the same shape, got \(2,\) and \(3,\)"):
        angle_error([0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match=r"q_estimate: expected shape \(\.\.\., 4\)"):
        attitude_error(np.zeros((2, 3)), q_true)
