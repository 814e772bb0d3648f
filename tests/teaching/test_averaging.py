import numpy as np
import pytest

from quadlib.teaching.averaging import batch_mean, exponential_average, half_average, recursive_mean


def test_batch_and_recursive_mean_equal_cumulative_mean():
    z = np.random.default_rng(1).normal(size=500)
    expected = np.cumsum(z) / np.arange(1, 501)
    np.testing.assert_allclose(batch_mean(z), expected, atol=1e-12)
    np.testing.assert_allclose(recursive_mean(z), expected, atol=1e-12)


def test_exponential_average_recursion_and_limits():
    z = np.array([1.0, 2.0, 4.0])
    np.testing.assert_allclose(exponential_average(z, 0.25, x0=0.0), [0.75, 1.6875, 3.421875])
    np.testing.assert_array_equal(exponential_average(z, 0.0), z)  # follows the samples
    np.testing.assert_array_equal(exponential_average(z, 1.0, x0=7.0), [7.0, 7.0, 7.0])  # ignores them
    np.testing.assert_array_equal(half_average(z), exponential_average(z, 0.5))


def test_exponential_average_steady_state_variance():
    # for white noise of variance s^2 the stationary variance is s^2 (1 - a) / (1 + a)
    z = np.random.default_rng(2).normal(size=200_000)
    a = 0.9
    var = exponential_average(z, a)[1000:].var()
    assert var == pytest.approx((1 - a) / (1 + a), rel=0.05)


def test_averaging_input_errors():
    with pytest.raises(ValueError, match="z: expected at least one sample"):
        batch_mean([])
    with pytest.raises(ValueError, match=r"alpha: expected a number in \[0, 1\], got 1.5"):
        exponential_average([1.0], 1.5)
    with pytest.raises(ValueError, match="z: expected finite values"):
        recursive_mean([1.0, np.nan])
