import numpy as np
import pytest

from quadlib import Sensor
from quadlib.analysis.montecarlo import importance_posterior, propagate_samples
from quadlib.quad.quad1d import quad1d_range_sensor
from quadlib.quad.rangefinder import tilted_range_sensor
from quadlib.reference import ekf_update


def test_propagate_samples_matches_closed_form_moments():
    # E[z / cos φ] with z, φ independent: E[z] E[1/cos φ]; for φ ~ N(0, s²) use a series to order s⁴
    s = 0.1
    moments, y = propagate_samples(tilted_range_sensor(0.01).h, [2.0, 0.0], np.diag([0.05**2, s**2]),
                                   400_000, np.random.default_rng(0))
    expected = 2.0 * (1 + s**2 / 2 + 5 * s**4 / 8)
    assert y.shape == (400_000, 1)
    assert moments.mean[0] == pytest.approx(expected, abs=3 * np.sqrt(moments.cov[0, 0] / 400_000))


def test_importance_posterior_equals_the_kalman_update_for_a_linear_sensor():
    sensor = Sensor("height", ("z",), h=lambda x: np.asarray(x)[..., 1:2], H=lambda x: np.array([[0.0, 1.0]]),
                    R=[[0.2**2]])  # quad1d's range sensor, written to accept stacked states
    mu, P, z = np.array([0.5, 1.0]), np.array([[0.3, 0.1], [0.1, 0.4]]), np.array([1.6])
    post = importance_posterior(sensor, mu, P, z, 400_000, np.random.default_rng(1))
    kf_mean, kf_cov = ekf_update(sensor, mu, P, z, joseph=True)
    np.testing.assert_allclose(post.mean, kf_mean, atol=5e-3)
    np.testing.assert_allclose(post.cov, kf_cov, atol=5e-3)


def test_tilted_range_jacobian_matches_finite_differences():
    sensor, x, eps = tilted_range_sensor(0.01), np.array([2.0, 0.4]), 1e-6
    fd = np.array([(sensor.h(x + eps * e) - sensor.h(x - eps * e))[0] / (2 * eps) for e in np.eye(2)])
    np.testing.assert_allclose(sensor.H(x)[0], fd, rtol=1e-7)
    assert sensor.H(np.array([2.0, 0.0]))[0, 1] == 0.0  # flat in roll at zero roll


def test_bad_arguments_are_named():
    with pytest.raises(ValueError, match="n_samples: expected an int >= 2, got 1"):
        propagate_samples(np.sin, [0.0], [[1.0]], 1, np.random.default_rng(0))
    with pytest.raises(TypeError, match="rng: expected a numpy.random.Generator"):
        propagate_samples(np.sin, [0.0], [[1.0]], 10, 42)


def test_run_monte_carlo_tuned_kf_is_consistent_and_mistuned_is_not():
    from quadlib import LinearKF
    from quadlib.analysis.metrics import chi2_interval
    from quadlib.analysis.montecarlo import run_monte_carlo
    from quadlib.quad.quad1d import quad1d_model

    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    t = np.arange(0.0, 5.0 + 1e-9, 0.02)
    u = np.zeros((t.size, 1))
    filters = {"tuned": lambda x0, P0: LinearKF(model, x0, P0, 0.02),
               "Q/100": lambda x0, P0: LinearKF(quad1d_model(0.03), x0, P0, 0.02)}
    runs = run_monte_carlo(filters, model, [sensor], [0.0, 1.0], np.diag([0.25, 0.25]), t, u, 50,
                           np.random.default_rng(5))
    low, high = chi2_interval(2, 50)
    tuned, small_q = runs["tuned"], runs["Q/100"]
    assert tuned.errors.shape == (50, t.size, 2) and tuned.nis["range"].shape == (50, 51)
    # both filters saw the same flights, and errors are estimates minus that truth
    assert tuned.truth is small_q.truth and tuned.truth.shape == (50, t.size, 2)
    assert np.ptp(tuned.truth[:, 0, 1]) > 0.5  # the initial truth is drawn from the prior
    assert np.abs(tuned.errors - small_q.errors).max() > 0.01
    assert low < tuned.nees.mean() < high
    assert small_q.nees.mean() > 3 * high
    assert tuned.rejected["range"].sum() == 0


def test_run_monte_carlo_names_bad_arguments():
    from quadlib.analysis.montecarlo import run_monte_carlo
    from quadlib.quad.quad1d import quad1d_model

    model = quad1d_model(0.3)
    with pytest.raises(ValueError, match="n_runs: expected an int >= 1, got 0"):
        run_monte_carlo({"kf": None}, model, [], [0.0, 1.0], np.eye(2), [0.0, 0.1], None, 0, np.random.default_rng(0))
    with pytest.raises(ValueError, match="x0: expected shape \\(2,\\), got \\(3,\\)"):
        run_monte_carlo({"kf": None}, model, [], [0.0, 1.0, 2.0], np.eye(2), [0.0, 0.1], None, 1,
                        np.random.default_rng(0))


def test_run_monte_carlo_assumed_sensors_change_only_the_filter_model():
    from quadlib import LinearKF
    from quadlib.analysis.montecarlo import run_monte_carlo
    from quadlib.quad.quad1d import quad1d_model

    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    t = np.arange(0.0, 3.0 + 1e-9, 0.02)
    make = {"a": lambda x0, P0: LinearKF(model, x0, P0, 0.02), "b": lambda x0, P0: LinearKF(model, x0, P0, 0.02)}
    runs = run_monte_carlo(make, model, [sensor], [0.0, 1.0], np.eye(2) * 0.1, t, np.zeros((t.size, 1)), 5,
                           np.random.default_rng(1), assumed_sensors={"b": [quad1d_range_sensor(0.4)]})
    # same flights and samples, different assumed R: the claimed σ and the NIS change
    assert runs["b"].sigma[:, -1, 1].mean() > 1.5 * runs["a"].sigma[:, -1, 1].mean()
    assert runs["b"].nis["range"].mean() < 0.2 * runs["a"].nis["range"].mean()
    with pytest.raises(ValueError, match=r"assumed_sensors\['c'\]: expected 1 sensors"):
        run_monte_carlo(make, model, [sensor], [0.0, 1.0], np.eye(2), t, np.zeros((t.size, 1)), 1,
                        np.random.default_rng(1), assumed_sensors={"c": []})
