import numpy as np
import pytest

from quadlib.quad.height import height_model, range_sensor
from quadlib.quad.quad1d import climb_input
from quadlib.sim.simulate import gaussian_factor, sample_sensor, simulate_model, with_dropouts, with_outage
from quadlib.sim.trajectories import step_profile


def test_noise_free_simulation_follows_g():
    m = height_model(0.5)
    t = np.arange(0, 1.0001, 0.1)
    x = simulate_model(m, [2.0], t, np.full((t.size, 1), 1.0), np.random.default_rng(0), process_noise=False)
    np.testing.assert_allclose(x[:, 0], 2.0 + t, atol=1e-12)


def test_process_noise_has_model_variance():
    m = height_model(0.5)
    t = np.arange(0, 200, 0.1)
    x = simulate_model(m, [0.0], t, np.zeros((t.size, 1)), np.random.default_rng(1))
    steps = np.diff(x[:, 0])
    assert steps.std() == pytest.approx(0.5 * 0.1, rel=0.05)  # 2000 samples: sd of std ~1.6 %


def test_simulation_draws_the_same_noise_as_multivariate_normal():
    """The factor of Q(dt) is computed once per step length, yet every state equals, bit for bit,
    the loop that calls rng.multivariate_normal(0, Q(dt), method="eigh") at each step."""
    from quadlib.quad.quad3d import quad3d_model

    for model in (height_model(0.5), quad3d_model(0.3, 0.05)):
        t = np.cumsum(np.r_[0.0, np.tile([0.01, 0.02, 0.01000000001], 100)])  # three step lengths
        u = np.random.default_rng(1).normal(size=(t.size, model.dim_u))
        x0 = np.linspace(0.1, 0.2, model.dim_x)
        fast = simulate_model(model, x0, t, u, np.random.default_rng(7))
        rng, reference = np.random.default_rng(7), [x0]
        for k in range(1, t.size):
            dt = t[k] - t[k - 1]
            reference.append(model.g(reference[-1], u[k - 1], dt)
                             + rng.multivariate_normal(np.zeros(model.dim_x), model.Q(dt), method="eigh"))
        np.testing.assert_array_equal(fast, np.array(reference))


def test_gaussian_factor_reproduces_numpy_draws_and_warns_like_numpy():
    a = np.array([[2.0, 0.0], [1.0, 1.0], [0.0, 0.5]])
    cov = a @ a.T  # rank two: one eigenvalue zero, maybe a rounding below it
    factor = gaussian_factor(cov)
    np.testing.assert_allclose(factor @ factor.T, cov, atol=1e-14)
    a, b = np.random.default_rng(3), np.random.default_rng(3)
    for _ in range(50):
        np.testing.assert_array_equal((a.standard_normal((1, 3)) @ factor.T)[0],
                                      b.multivariate_normal(np.zeros(3), cov, method="eigh"))
    with pytest.warns(RuntimeWarning, match="positive-semidefinite"):
        gaussian_factor([[1.0, 0.0], [0.0, -1.0]])


def test_sample_sensor_rate_noise_and_seed():
    s = range_sensor(0.3, rate_hz=10)
    t = np.arange(0, 100, 0.01)
    x = np.full((t.size, 1), 5.0)
    meas = sample_sensor(s, t, x, np.random.default_rng(2))
    assert meas.t.size == 1000 and np.allclose(np.diff(meas.t), 0.1)
    assert meas.z.std() == pytest.approx(0.3, rel=0.07) and meas.z.mean() == pytest.approx(5.0, abs=0.03)
    again = sample_sensor(s, t, x, np.random.default_rng(2))
    np.testing.assert_array_equal(meas.z, again.z)


def test_dropouts_fraction():
    s = range_sensor(0.3)
    t = np.arange(0, 100, 0.01)
    meas = sample_sensor(s, t, np.zeros((t.size, 1)), np.random.default_rng(3))
    holed = with_dropouts(meas, np.random.default_rng(4), 0.2)
    assert np.isnan(holed.z).mean() == pytest.approx(0.2, abs=0.02)
    assert not np.isnan(meas.z).any()  # the original is untouched


def test_an_outage_empties_exactly_its_window_and_keeps_the_rest():
    s = range_sensor(0.3)
    t = np.arange(0, 10, 0.1)
    meas = sample_sensor(s, t, np.zeros((t.size, 1)), np.random.default_rng(3))
    cut = with_outage(meas, 2.0, 3.0)
    inside = (t >= 2.0) & (t < 3.0)
    assert np.isnan(cut.z[inside]).all() and inside.sum() == 10
    assert np.array_equal(cut.z[~inside], meas.z[~inside]) and cut.sensor is meas.sensor
    assert not np.isnan(meas.z).any()  # the original is untouched


def test_the_climb_input_rises_and_returns_to_rest():
    dt = 0.02
    t = np.arange(0.0, 20.0 + dt / 2, dt)
    u = climb_input(t)
    assert u.shape == (t.size, 1)
    assert u[t < 1].max() == 0.0 and u[(t >= 1) & (t < 3), 0].min() == 1.0 and u[t >= 14].max() == 0.0
    velocity = np.cumsum(u[:, 0]) * dt
    assert abs(velocity[-1]) < 1e-9, "every climb is braked: the vehicle ends at rest"
    assert np.sum(velocity) * dt == pytest.approx(4.0 - 2.0, abs=0.05), "climbs 4 m, then descends 2 m"


def test_rng_required():
    with pytest.raises(TypeError, match="rng: expected a numpy.random.Generator"):
        simulate_model(height_model(0.1), [0.0], [0.0, 1.0], [[0.0], [0.0]], 42)


def test_step_profile():
    np.testing.assert_array_equal(step_profile([0, 1, 2, 3], 2, 1.0, 5.0), [1, 1, 5, 5])
