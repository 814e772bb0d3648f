import numpy as np
import pytest
from filterpy.discrete_bayes import predict, update

from quadlib.teaching.histogram import (
    belief_mean_std,
    gaussian_belief,
    gaussian_kernel,
    gaussian_likelihood,
    uniform_grid,
)


def test_uniform_grid():
    g = uniform_grid(0.0, 1.0, 0.25)
    np.testing.assert_allclose(g, [0, 0.25, 0.5, 0.75, 1.0])
    with pytest.raises(ValueError, match="high: expected a value > low"):
        uniform_grid(1.0, 0.0, 0.1)


def test_kernel_is_normalised_discrete_gaussian():
    k = gaussian_kernel(2.0)
    assert k.size == 21 and k.sum() == pytest.approx(1.0)
    offsets = np.arange(-10, 11)
    assert offsets @ k == pytest.approx(0.0, abs=1e-15)
    # a cell-averaged Gaussian has variance sigma^2 + 1/12 (Sheppard's correction)
    assert (offsets**2) @ k == pytest.approx(4.0 + 1 / 12, rel=1e-4)


def test_gaussian_belief_moments():
    grid = uniform_grid(0, 10, 0.01)
    mean, std = belief_mean_std(grid, gaussian_belief(grid, 4.0, 0.5))
    assert mean == pytest.approx(4.0, abs=1e-9) and std == pytest.approx(np.sqrt(0.25 + 0.01**2 / 12), rel=1e-6)


def test_predict_update_match_gaussian_algebra():
    grid = uniform_grid(0, 10, 0.01)
    prior = gaussian_belief(grid, 3.0, 0.4)
    moved = predict(prior, 50, gaussian_kernel(30.0), mode="constant")
    m, s = belief_mean_std(grid, moved)
    assert m == pytest.approx(3.5, abs=1e-6) and s == pytest.approx(0.5, abs=1e-3)  # sqrt(0.4^2 + 0.3^2)
    post = update(gaussian_likelihood(grid, 4.0, 0.5), moved)
    m, s = belief_mean_std(grid, post)
    assert m == pytest.approx(3.75, abs=1e-3) and s == pytest.approx(np.sqrt(0.125), abs=1e-3)


def test_mixture_likelihood_has_floor():
    grid = uniform_grid(0, 10, 0.1)
    lik = gaussian_likelihood(grid, 2.0, 0.3, outlier_probability=0.1)
    assert lik.min() == pytest.approx(0.1 / 10)
    with pytest.raises(ValueError, match=r"outlier_probability: expected a number in \[0, 1\)"):
        gaussian_likelihood(grid, 2.0, 0.3, outlier_probability=1.0)


def test_belief_errors():
    grid = uniform_grid(0, 1, 0.5)
    with pytest.raises(ValueError, match=r"belief: expected shape \(3,\) to match grid"):
        belief_mean_std(grid, [1.0, 0.0])
    with pytest.raises(ValueError, match="belief: expected non-negative"):
        belief_mean_std(grid, [1.0, -1.0, 0.5])
    with pytest.raises(ValueError, match="mean: N"):
        gaussian_belief(grid, 100.0, 0.01)


def test_kernel_of_zero_half_width_is_identity():
    np.testing.assert_array_equal(gaussian_kernel(1.0, half_width=0), [1.0])
