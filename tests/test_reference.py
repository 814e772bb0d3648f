"""The plain-numpy textbook filters equal filterpy and quadlib's wrappers to 1e-10."""

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter, MerweScaledSigmaPoints

from quadlib import LinearKF, ModelEKF, ModelUKF, Sensor
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
from quadlib.reference import ekf_predict, ekf_update, sigma_points, ukf_predict, ukf_update
from quadlib.sim.simulate import sample_sensor, simulate_model

DT = 0.02


def quad2d_log(seed=7, n=500):
    model, sensor = quad2d_model(0.2, 0.01), quad2d_range_sensor(0.05, rate_hz=1 / DT)
    rng = np.random.default_rng(seed)
    t = DT * np.arange(n)
    u = 0.2 * np.sin(0.8 * t)[:, None]
    x = simulate_model(model, [0.0, 0.0, 0.0], t, u, rng)
    return model, sensor, u, sample_sensor(sensor, t, x, rng).z


@pytest.mark.parametrize("joseph", [False, True])
def test_algorithm_2_equals_filterpy_kalman_filter_and_the_wrappers_on_the_1d_quad(joseph):
    model, sensor = quad1d_model(0.5), quad1d_range_sensor(0.1)
    rng = np.random.default_rng(1)
    mu, Sigma = np.array([0.0, 1.0]), np.diag([1.0, 0.5])
    kf = KalmanFilter(dim_x=2, dim_z=1, dim_u=1)
    kf.x, kf.P = mu.reshape(-1, 1).copy(), Sigma.copy()
    kf.F, kf.B, kf.Q = model.G(mu, [0.0], DT), model.B(mu, [0.0], DT), model.Q(DT)
    kf.H, kf.R = sensor.H(mu), sensor.R
    wrapped = [LinearKF(model, mu, Sigma, DT), ModelEKF(model, mu, Sigma, DT)]
    for _ in range(400):
        u, z = rng.normal(size=1), 1.0 + 0.1 * rng.normal(size=1)
        mu, Sigma = ekf_predict(model, mu, Sigma, u, DT)
        mu, Sigma = ekf_update(sensor, mu, Sigma, z, joseph=joseph)
        kf.predict(u=u.reshape(1, 1))
        kf.update(z.reshape(1, 1))
        for f in wrapped:
            f.predict(u)
            f.update_sensor(sensor, z)
    for x, P in [(kf.x[:, 0], kf.P)] + [(f.estimate, f.P) for f in wrapped]:
        np.testing.assert_allclose(x, mu, rtol=0, atol=1e-10)
        np.testing.assert_allclose(P, Sigma, rtol=0, atol=1e-10)


def test_algorithm_2_equals_model_ekf_on_the_nonlinear_2d_quad():
    model, sensor, u, zs = quad2d_log()
    mu, Sigma = np.array([0.0, 0.0, 0.0]), np.diag([0.01, 0.1, 0.1])
    ekf = ModelEKF(model, mu, Sigma, DT)
    for k in range(1, len(zs)):
        mu, Sigma = ekf_update(sensor, *ekf_predict(model, mu, Sigma, u[k - 1], DT), zs[k])
        ekf.predict(u[k - 1])
        ekf.update_sensor(sensor, zs[k])
        np.testing.assert_allclose(ekf.estimate, mu, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ekf.P, Sigma, rtol=0, atol=1e-10)


@pytest.mark.parametrize("alpha, beta, kappa", [(1e-3, 2.0, 0.0), (0.5, 2.0, 0.0), (1.0, 0.0, 0.0)])
def test_sigma_points_equal_merwe_scaled_sigma_points(alpha, beta, kappa):
    rng = np.random.default_rng(2)
    A = rng.normal(size=(3, 3))
    mu, Sigma = rng.normal(size=3), A @ A.T + 0.1 * np.eye(3)
    X, wm, wc = sigma_points(mu, Sigma, alpha, beta, kappa)
    ref = MerweScaledSigmaPoints(3, alpha=alpha, beta=beta, kappa=kappa)
    np.testing.assert_allclose(X, ref.sigma_points(mu, Sigma), rtol=0, atol=1e-12)
    np.testing.assert_allclose(wm, ref.Wm, rtol=1e-12)
    np.testing.assert_allclose(wc, ref.Wc, rtol=1e-12)
    # the points reproduce the mean and covariance exactly (the centre point adds nothing to the latter)
    np.testing.assert_allclose(wm @ X, mu, atol=1e-9)
    np.testing.assert_allclose((X - mu).T @ (wc[:, None] * (X - mu)), Sigma, atol=1e-9)


def test_algorithm_3_equals_model_ukf_on_the_nonlinear_2d_quad():
    model, sensor, u, zs = quad2d_log()
    a, b, k = 0.5, 2.0, 0.0
    mu, Sigma = np.array([0.0, 0.0, 0.0]), np.diag([0.01, 0.1, 0.1])
    ukf = ModelUKF(model, mu, Sigma, DT, alpha=a, beta=b, kappa=k)
    for i in range(1, len(zs)):
        mu, Sigma = ukf_update(sensor, *ukf_predict(model, mu, Sigma, u[i - 1], DT, a, b, k), zs[i], a, b, k)
        ukf.predict(u[i - 1])
        ukf.update_sensor(sensor, zs[i])
        np.testing.assert_allclose(ukf.estimate, mu, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ukf.P, Sigma, rtol=0, atol=1e-10)


def test_reference_filters_refuse_sensors_with_a_custom_residual():
    angle = Sensor("yaw", ("psi",), h=lambda x: x[:1], H=lambda x: np.eye(1), R=[[0.1]],
                   residual=lambda a, b: np.angle(np.exp(1j * (a - b))))
    with pytest.raises(ValueError, match="plain residual z - h\\(x\\) only; 'yaw'"):
        ekf_update(angle, np.zeros(1), np.eye(1), np.zeros(1))
