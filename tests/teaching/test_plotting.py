import matplotlib.pyplot as plt
import numpy as np

from quadlib.analysis.metrics import chi2_interval
from quadlib.teaching.plotting import plot_consistency, plot_estimate, plot_innovations


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
