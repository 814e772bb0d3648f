"""NEES and NIS against their χ² band, and log axes labelled with a few plain numbers."""

import numpy as np
import pytest
from matplotlib.figure import Figure

from quadlib.analysis.metrics import chi2_interval
from quadlib.teaching import plot_chi2_band, readable_log_axis


def _axes():
    return Figure().subplots()


def test_the_band_is_the_chi2_interval_of_the_mean_and_the_series_is_drawn():
    ax = plot_chi2_band([0.0, 1.0, 2.0], [1.8, np.nan, 2.2], 2, n_runs=50, ax=_axes())
    (band,) = ax.patches
    np.testing.assert_allclose([band.get_y(), band.get_y() + band.get_height()], chi2_interval(2, 50))
    line = [ln for ln in ax.get_lines() if ln.get_label().startswith("mean NEES")][0]
    np.testing.assert_array_equal(line.get_ydata(), [1.8, np.nan, 2.2])
    assert ax.get_yscale() == "linear" and ax.get_ylabel() == "mean NEES"
    labels = ax.get_legend_handles_labels()[1]
    assert labels == ["95% χ² band (50 runs)", "expected value", "mean NEES, 50 runs"]


def test_values_that_span_decades_get_a_log_axis_with_plain_labels():
    ax = plot_chi2_band(np.arange(4.0), [0.5, 3.0, 40.0, 60.0], 1, n_runs=20, ax=_axes(), name="NIS", marker=".")
    assert ax.get_yscale() == "log"
    ax.figure.canvas.draw()
    shown = [t.get_text() for t in ax.get_yticklabels() if ax.get_ylim()[0] <= t.get_position()[1] <= ax.get_ylim()[1]]
    assert shown == ["1", "10"]
    assert all("10^" not in s and "$" not in s for s in shown)


@pytest.mark.parametrize(("limits", "expected"), [((0.5, 80.0), ["1", "10"]), ((1.2, 30.0), ["2", "5", "10", "20"]),
                                                  ((1.1, 2.9), ["1.5", "2"])])
def test_a_log_axis_shows_the_coarsest_round_ticks_that_give_two_labels(limits, expected):
    ax = _axes()
    ax.set_yscale("log")
    ax.set_ylim(*limits)
    readable_log_axis(ax)
    ax.figure.canvas.draw()
    low, high = ax.get_ylim()
    shown = [t.get_text() for t in ax.get_yticklabels() if low <= t.get_position()[1] <= high]
    assert shown == expected


def test_a_linear_axis_or_a_bad_series_is_named():
    ax = _axes()
    with pytest.raises(ValueError, match="ax: expected a logarithmic y axis"):
        readable_log_axis(ax)
    with pytest.raises(ValueError, match="axis: expected 'x' or 'y'"):
        readable_log_axis(ax, "z")
    with pytest.raises(ValueError, match="values: expected one value per time"):
        plot_chi2_band([0.0, 1.0], [1.0], 2, ax=ax)
    with pytest.raises(ValueError, match="yscale: expected one of"):
        plot_chi2_band([0.0, 1.0], [1.0, 2.0], 2, ax=ax, yscale="logit")
