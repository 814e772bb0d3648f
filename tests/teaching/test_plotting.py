import matplotlib.pyplot as plt
import numpy as np
import pytest

from quadlib.analysis.metrics import chi2_interval
from quadlib.teaching.plotting import (
    covariance_ellipse,
    plot_consistency,
    plot_covariance_ellipse,
    plot_estimate,
    plot_innovations,
)


def test_plot_estimate_band_and_lines():
    t = np.linspace(0, 1, 11)
    ax = plot_estimate(t, t, sigma=np.full(11, 0.1), truth=t + 0.05, k=3, measurements=(t, t))
    labels = [line.get_label() for line in ax.get_lines()]
    assert labels == ["measurements", "truth", "estimate"]
    band = ax.collections[0].get_paths()[0].vertices
    assert np.isclose(band[:, 1].max(), 1.3) and np.isclose(band[:, 1].min(), -0.3)
    plt.close(ax.figure)


def test_plot_innovations_bounds():
    t = np.arange(5.0)
    ax = plot_innovations(t, np.zeros(5), np.full(5, 4.0), k=2)
    np.testing.assert_allclose(ax.get_lines()[1].get_ydata(), 4.0)
    plt.close(ax.figure)


def test_plot_consistency_draws_chi2_interval_on_given_axes():
    fig, axes = plt.subplots(1, 2)
    out = plot_consistency(np.arange(3.0), [1.0, 2.0, 3.0], dof=2, n_runs=50, ax=axes[1])
    assert out is axes[1] and not axes[0].get_lines()
    low, high = chi2_interval(2, 50)
    ys = sorted(line.get_ydata()[0] for line in out.get_lines()[1:])
    np.testing.assert_allclose(ys, sorted([low, high, 2.0]))
    plt.close(fig)


def test_the_ellipse_is_the_k_sigma_contour_of_the_gaussian():
    mean, cov = np.array([1.0, -2.0]), np.array([[4.0, 1.5], [1.5, 1.0]])
    boundary = covariance_ellipse(mean, cov, k=2.0, points=50)
    d = boundary - mean
    np.testing.assert_allclose(np.einsum("ni,ij,nj->n", d, np.linalg.inv(cov), d), 4.0, rtol=1e-12)
    np.testing.assert_allclose(boundary[0], boundary[-1])
    # its extent along x is k σ_x: the contour's widest point
    assert np.isclose(covariance_ellipse(mean, cov, k=2.0, points=2001)[:, 0].max() - mean[0], 2.0 * 2.0, rtol=1e-5)
    flat = covariance_ellipse([0.0, 0.0], [[1.0, 0.0], [0.0, 0.0]], k=1.0)  # degenerate: a segment
    assert np.allclose(flat[:, 1], 0.0) and np.isclose(flat[:, 0].max(), 1.0)


def test_the_ellipse_refuses_what_is_not_a_covariance():
    with pytest.raises(ValueError, match="cov: expected a symmetric"):
        covariance_ellipse([0.0, 0.0], [[1.0, 0.5], [0.0, 1.0]])
    with pytest.raises(ValueError, match="cov: expected a positive semi-definite"):
        covariance_ellipse([0.0, 0.0], [[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(ValueError, match="mean: expected shape"):
        covariance_ellipse([0.0], np.eye(2))


def test_plot_covariance_ellipse_draws_on_the_given_axes():
    fig, ax = plt.subplots()
    out = plot_covariance_ellipse([0.0, 0.0], np.eye(2), k=1.0, ax=ax, color="C3", label="prior")
    assert out is ax and ax.get_lines()[0].get_label() == "prior"
    np.testing.assert_allclose(np.hypot(*ax.get_lines()[0].get_data()), 1.0)
    plt.close(fig)
