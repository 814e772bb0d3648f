import matplotlib.pyplot as plt
import numpy as np
import pytest

from quadlib.teaching.sigma_plots import plot_sigma_points


def test_areas_follow_the_weights_and_negative_weights_are_hollow():
    X = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    w = np.array([-3.0, 1.0, 1.0, 1.0, 1.0])
    fig, ax = plt.subplots()
    out = plot_sigma_points(X, w, ax=ax, size=90.0, label="points")
    assert out is ax
    filled, hollow = ax.collections
    np.testing.assert_allclose(filled.get_offsets(), X[1:])
    np.testing.assert_allclose(filled.get_sizes(), 30.0)  # |1| / |-3| of the heaviest area
    np.testing.assert_allclose(hollow.get_offsets(), X[:1])
    np.testing.assert_allclose(hollow.get_sizes(), 90.0)
    assert hollow.get_facecolor().size == 0 or np.allclose(hollow.get_facecolor()[:, 3], 0.0)
    assert [t.get_text() for t in ax.texts] == ["-3.00", "+1.00", "+1.00", "+1.00", "+1.00"]
    assert filled.get_label() == "points"
    plt.close(fig)


def test_coinciding_points_get_one_label_and_annotations_can_be_off():
    X = np.array([[0.0, 0.0], [0.0, 0.0], [1.0, 1.0]])
    ax = plot_sigma_points(X, [0.5, 0.25, 0.25], fmt=".1f")
    assert [t.get_text() for t in ax.texts] == ["0.5", "0.2"]
    plt.close(ax.figure)
    ax = plot_sigma_points(X, [0.5, 0.25, 0.25], annotate=False)
    assert not ax.texts and len(ax.collections) == 1
    plt.close(ax.figure)


def test_unique_labels_each_weight_once_and_a_zero_weight_stays_visible():
    X = np.array([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    ax = plot_sigma_points(X, [0.0, 0.25, 0.25, 0.25, 0.25], annotate="unique", size=100.0)
    assert [t.get_text() for t in ax.texts] == ["+0.00", "+0.25"]
    np.testing.assert_allclose(ax.collections[0].get_sizes(), [5.0, 100.0, 100.0, 100.0, 100.0])
    plt.close(ax.figure)


def test_refuses_what_is_not_a_set_of_weighted_points():
    with pytest.raises(ValueError, match="points: expected shape"):
        plot_sigma_points(np.zeros((3, 3)), np.ones(3))
    with pytest.raises(ValueError, match="weights: expected shape"):
        plot_sigma_points(np.zeros((3, 2)), np.ones(2))
    with pytest.raises(ValueError, match="fmt: expected a float format"):
        plot_sigma_points(np.zeros((1, 2)), [1.0], fmt="d")
    with pytest.raises(TypeError, match="annotate"):
        plot_sigma_points(np.zeros((1, 2)), [1.0], annotate="yes")
