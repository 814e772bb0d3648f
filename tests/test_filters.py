from dataclasses import replace

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from quadlib import LinearKF, Model, ModelEKF, ModelUKF, Sensor
from quadlib.model_filter import gate_threshold
from quadlib.quad.height import height_model, range_sensor


def constant_velocity(sigma_a=0.5):
    """Linear [p, v] model with acceleration input and white-acceleration noise."""
    def Q(dt):
        return sigma_a**2 * np.array([[dt**4 / 4, dt**3 / 2], [dt**3 / 2, dt**2]])
    return Model(("p", "v"), ("a",), g=lambda x, u, dt: np.array([x[0] + dt * x[1] + 0.5 * dt**2 * u[0],
                                                                   x[1] + dt * u[0]]),
                 G=lambda x, u, dt: np.array([[1.0, dt], [0.0, 1.0]]),
                 B=lambda x, u, dt: np.array([[0.5 * dt**2], [dt]]), Q=Q, name="cv")


def position_sensor(sigma=0.3):
    return Sensor("pos", ("p",), h=lambda x: x[:1].copy(), H=lambda x: np.array([[1.0, 0.0]]),
                  R=[[sigma**2]])


def velocity_sensor(sigma=0.1):
    return Sensor("vel", ("v",), h=lambda x: x[1:2].copy(), H=lambda x: np.array([[0.0, 1.0]]),
                  R=[[sigma**2]])


def pendulum():
    """Nonlinear [angle, rate] model with a nonlinear range-like sensor."""
    model = Model(("theta", "omega"), ("torque",),
                  g=lambda x, u, dt: np.array([x[0] + dt * x[1], x[1] + dt * (-9.81 * np.sin(x[0]) + u[0])]),
                  G=lambda x, u, dt: np.array([[1.0, dt], [-9.81 * dt * np.cos(x[0]), 1.0]]),
                  Q=lambda dt: np.diag([1e-6, 1e-4]), name="pendulum")
    sensor = Sensor("horiz", ("x",), h=lambda x: np.array([np.sin(x[0])]),
                    H=lambda x: np.array([[np.cos(x[0]), 0.0]]), R=[[0.01]])
    return model, sensor


def test_kf_ekf_ukf_agree_on_linear_model():
    model, pos, vel = constant_velocity(), position_sensor(), velocity_sensor()
    rng = np.random.default_rng(3)
    filters = [cls(model, [0.0, 1.0], np.diag([1.0, 0.5]), 0.01) for cls in (LinearKF, ModelEKF, ModelUKF)]
    for k in range(300):
        u = rng.normal(size=1)
        for f in filters:
            f.predict(u)
        if k % 5 == 0:
            z = rng.normal(size=1)
            for f in filters:
                f.update_sensor(pos, z)
        if k % 7 == 0:  # a second sensor in some of the same steps
            z = rng.normal(size=1)
            for f in filters:
                f.update_sensor(vel, z)
    ref = filters[0]
    for f in filters[1:]:
        np.testing.assert_allclose(f.estimate, ref.estimate, atol=1e-10)
        np.testing.assert_allclose(f.P, ref.P, atol=1e-10)


def test_linear_kf_matches_bare_filterpy():
    model, pos = constant_velocity(), position_sensor()
    ours = LinearKF(model, [0.0, 0.0], np.eye(2), 0.1)
    bare = KalmanFilter(dim_x=2, dim_z=1, dim_u=1)
    bare.x, bare.P = np.zeros((2, 1)), np.eye(2)
    bare.F, bare.B, bare.H, bare.R, bare.Q = model.G(None, None, 0.1), model.B(None, None, 0.1), \
        np.array([[1.0, 0.0]]), np.array([[0.09]]), model.Q(0.1)
    for z, u in [(0.1, 0.5), (0.4, -0.2), (0.3, 0.0)]:
        ours.predict([u])
        bare.predict(u=np.array([[u]]))
        ours.update_sensor(pos, [z])
        bare.update(np.array([[z]]))
    np.testing.assert_allclose(ours.estimate, bare.x[:, 0], atol=1e-14)
    np.testing.assert_allclose(ours.P, bare.P, atol=1e-14)


def test_ekf_predict_uses_nonlinear_g_and_jacobian_at_previous_mean():
    model, _ = pendulum()
    x0, P0, dt = np.array([1.2, 0.3]), np.diag([0.04, 0.01]), 0.05
    ekf = ModelEKF(model, x0, P0, dt)
    ekf.predict([0.7])
    G = model.G(x0, [0.7], dt)
    np.testing.assert_allclose(ekf.estimate, model.g(x0, [0.7], dt), atol=1e-15)
    np.testing.assert_allclose(ekf.P, G @ P0 @ G.T + model.Q(dt), atol=1e-15)
    np.testing.assert_allclose(ekf.x_prior[:, 0], model.g(x0, [0.7], dt), atol=1e-15)


def test_ekf_matches_algorithm_2_written_out():
    """Tellex et al. Algorithm 2, in plain numpy, against the wrapper on a nonlinear problem."""
    model, sensor = pendulum()
    rng = np.random.default_rng(7)
    mu, Sigma, dt = np.array([0.5, 0.0]), np.diag([0.1, 0.1]), 0.02
    ekf = ModelEKF(model, mu, Sigma, dt)
    for _ in range(200):
        u, z = rng.normal(size=1), np.sin(0.5) + 0.1 * rng.normal(size=1)
        G = model.G(mu, u, dt)
        mu, Sigma = model.g(mu, u, dt), G @ Sigma @ G.T + model.Q(dt)
        H = sensor.H(mu)
        K = Sigma @ H.T @ np.linalg.inv(H @ Sigma @ H.T + sensor.R)
        mu = mu + K @ (z - sensor.h(mu))
        Sigma = (np.eye(2) - K @ H) @ Sigma
        ekf.predict(u)
        ekf.update_sensor(sensor, z)
    np.testing.assert_allclose(ekf.estimate, mu, atol=1e-10)
    np.testing.assert_allclose(ekf.P, Sigma, atol=1e-10)


def test_ukf_passes_input_to_g():
    model = constant_velocity()
    ukf = ModelUKF(model, [1.0, 2.0], np.eye(2) * 1e-3, 0.1)
    ukf.predict([3.0])
    np.testing.assert_allclose(ukf.estimate, model.g(np.array([1.0, 2.0]), np.array([3.0]), 0.1), atol=1e-12)


def test_ukf_update_before_first_predict_is_correct():
    model, pos = constant_velocity(), position_sensor()
    kf = LinearKF(model, [0.0, 0.0], np.eye(2), 0.1)
    ukf = ModelUKF(model, [0.0, 0.0], np.eye(2), 0.1)
    for f in (kf, ukf):
        f.update_sensor(pos, [1.0])
    np.testing.assert_allclose(ukf.estimate, kf.estimate, atol=1e-12)
    assert ukf.estimate[0] == pytest.approx(1.0 / 1.09)


def test_angle_residual_is_wrapped():
    def wrap(a):
        return (a + np.pi) % (2 * np.pi) - np.pi
    model = Model(("psi",), (), g=lambda x, u, dt: x, G=lambda x, u, dt: np.eye(1), Q=lambda dt: np.eye(1) * 1e-6)
    compass = Sensor("yaw", ("psi",), h=lambda x: x.copy(), H=lambda x: np.eye(1), R=[[0.01]],
                     residual=lambda z, zh: wrap(z - zh))
    for cls in (ModelEKF, ModelUKF):
        f = cls(model, [np.pi - 0.01], [[0.01]], 0.1)
        inn = f.update_sensor(compass, [-np.pi + 0.01])
        assert inn.y[0] == pytest.approx(0.02, abs=1e-12), cls.__name__


def test_gate_rejects_outlier_and_keeps_state():
    model, pos = constant_velocity(), position_sensor(0.3)
    for cls in (LinearKF, ModelEKF, ModelUKF):
        f = cls(model, [0.0, 0.0], np.eye(2) * 0.01, 0.1)
        x, P = f.estimate, f.P.copy()
        inn = f.update_sensor(pos, [30.0], gate_probability=0.999)
        assert not inn.accepted and inn.nis > gate_threshold(1, 0.999)
        np.testing.assert_array_equal(f.estimate, x)
        np.testing.assert_array_equal(f.P, P)
        ok = f.update_sensor(pos, [0.1], gate_probability=0.999)
        assert ok.accepted and f.estimate[0] > 0


def test_gate_threshold_is_chi2_quantile():
    assert gate_threshold(1, 0.95) == pytest.approx(3.841458820694124)
    assert gate_threshold(2, 0.99) == pytest.approx(9.210340371976182)


def test_linear_kf_refuses_nonlinear_model_and_sensor():
    model, sensor = pendulum()
    with_b = replace(model, B=lambda x, u, dt: np.array([[0.0], [dt]]))
    with pytest.raises(ValueError, match="model: 'pendulum' is not linear"):
        LinearKF(with_b, [0.0, 0.0], np.eye(2), 0.1)
    kf = LinearKF(constant_velocity(), [0.0, 0.0], np.eye(2), 0.1)
    with pytest.raises(ValueError, match="sensor: 'horiz' is not linear"):
        kf.update_sensor(sensor, [0.1])
    no_b = Model(("p",), ("a",), g=lambda x, u, dt: x + u, G=lambda x, u, dt: np.eye(1), Q=lambda dt: np.eye(1))
    with pytest.raises(ValueError, match="has inputs but no B"):
        LinearKF(no_b, [0.0], [[1.0]], 0.1)


def test_constructor_and_update_arguments_checked():
    model = height_model(0.1)
    with pytest.raises(ValueError, match=r"x0: expected shape \(1,\), got \(2,\)"):
        ModelEKF(model, [0.0, 1.0], [[1.0]], 0.1)
    with pytest.raises(ValueError, match="P0: expected a positive semi-definite"):
        ModelUKF(model, [0.0], [[-1.0]], 0.1)
    with pytest.raises(ValueError, match="dt: expected a finite number > 0"):
        LinearKF(model, [0.0], [[1.0]], 0.0)
    with pytest.raises(TypeError, match="model: expected a quadlib Model"):
        ModelEKF("height", [0.0], [[1.0]], 0.1)
    f = ModelEKF(model, [0.0], [[1.0]], 0.1)
    with pytest.raises(ValueError, match=r"z \(range\): expected finite values, got 1 NaN"):
        f.update_sensor(range_sensor(0.1), [np.nan])
    with pytest.raises(TypeError, match="sensor: expected a quadlib Sensor"):
        f.update_sensor("range", [1.0])
    with pytest.raises(ValueError, match=r"u: expected shape \(1,\), got \(2,\)"):
        f.predict([1.0, 2.0])
    with pytest.raises(ValueError, match="gate_probability: expected a number in"):
        f.update_sensor(range_sensor(0.1), [1.0], gate_probability=1.5)


def test_divergence_is_reported_not_silent():
    model = Model(("a",), (), g=lambda x, u, dt: x * 1e200, G=lambda x, u, dt: np.eye(1) * 1e200,
                  Q=lambda dt: np.eye(1))
    f = ModelEKF(model, [1e200], [[1.0]], 0.1)
    with np.errstate(over="ignore"):
        with pytest.raises(FloatingPointError, match="ModelEKF.predict: the state or covariance became non-finite"):
            f.predict()


def test_ukf_gives_the_same_answer_whether_x_is_edited_in_place_or_replaced():
    model, sensor = pendulum()
    results = []
    for edit in ("in place", "replaced"):
        f = ModelUKF(model, [0.1, 0.0], np.eye(2) * 0.01, 0.05)
        f.predict([0.0])
        if edit == "in place":
            f.x[0] = 0.3
        else:
            f.x = np.array([0.3, f.x[1]])
        f.update_sensor(sensor, [0.25])
        results.append(f.estimate)
    np.testing.assert_array_equal(results[0], results[1])


def _additive_as_error_state(model):
    """The same model declared as an error-state model whose ⊞ and ⊟ are + and −."""
    return replace(model, error_names=tuple(f"d{n}" for n in model.state_names),
                   state_add=lambda x, d: x + d, residual_x=lambda a, b: a - b)


@pytest.mark.parametrize("cls", [ModelEKF, ModelUKF])
def test_an_error_state_model_with_plain_addition_is_the_additive_filter(cls):
    model, sensor = pendulum()
    plain, error = cls(model, [0.2, 0.1], np.eye(2) * 0.05, 0.05), cls(_additive_as_error_state(model), [0.2, 0.1],
                                                                         np.eye(2) * 0.05, 0.05)
    for k in range(40):
        for f in (plain, error):
            f.predict([0.3 * np.sin(k / 5)])
            f.update_sensor(sensor, [np.sin(0.2 + 0.01 * k)])
        np.testing.assert_allclose(error.estimate, plain.estimate, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(error.P, plain.P, rtol=1e-10, atol=1e-14)
        assert np.all(error.x == 0.0)  # the error is folded into the nominal state after every step


def test_a_rejected_sample_leaves_an_error_state_filter_untouched():
    model, sensor = pendulum()
    f = ModelEKF(_additive_as_error_state(model), [0.2, 0.1], np.eye(2) * 0.05, 0.05)
    before = (f.estimate, f.P.copy())
    inn = f.update_sensor(sensor, [50.0], gate_probability=0.99)
    assert not inn.accepted
    np.testing.assert_array_equal(f.estimate, before[0])
    np.testing.assert_array_equal(f.P, before[1])


def test_normalize_is_applied_after_predict_and_update():
    calls = []

    def unit(x):
        calls.append(1)
        return x / np.linalg.norm(x)

    model = Model(("a", "b"), (), g=lambda x, u, dt: 1.1 * x, G=lambda x, u, dt: 1.1 * np.eye(2),
                  Q=lambda dt: 1e-4 * np.eye(2), normalize=unit)
    sensor = Sensor("a", ("a",), h=lambda x: x[:1], H=lambda x: np.array([[1.0, 0.0]]), R=[[0.01]])
    for cls in (ModelEKF, ModelUKF):
        f = cls(model, [0.6, 0.8], np.eye(2) * 0.01, 0.1)
        f.predict()
        assert np.linalg.norm(f.estimate) == pytest.approx(1.0)
        f.update_sensor(sensor, [0.9])
        assert np.linalg.norm(f.estimate) == pytest.approx(1.0)
    assert len(calls) == 6  # x0, predict, update for each filter


def test_a_sensor_with_context_gets_each_samples_context():
    model, _ = pendulum()
    scaled = Sensor("scaled", ("s",), context_names=("gain",), h=lambda x, c: np.array([c[0] * np.sin(x[0])]),
                    H=lambda x, c: np.array([[c[0] * np.cos(x[0]), 0.0]]), R=[[0.01]])
    plain = Sensor("scaled", ("s",), h=lambda x: np.array([2.0 * np.sin(x[0])]),
                   H=lambda x: np.array([[2.0 * np.cos(x[0]), 0.0]]), R=[[0.01]])
    a, b = (ModelEKF(model, [0.2, 0.0], np.eye(2) * 0.05, 0.05) for _ in range(2))
    a.update_sensor(scaled, [0.5], context=[2.0])
    b.update_sensor(plain, [0.5])
    np.testing.assert_array_equal(a.estimate, b.estimate)
    with pytest.raises(ValueError, match=r"context \(scaled\): expected shape \(1,\), got \(2,\)"):
        a.update_sensor(scaled, [0.5], context=[1.0, 2.0])
    with pytest.raises(ValueError, match="context \\(scaled\\): expected None"):
        b.update_sensor(plain, [0.5], context=[2.0])


def test_model_and_filter_arguments_for_the_new_features_are_checked():
    model, _ = pendulum()
    with pytest.raises(ValueError, match="Model.error_names: an error-state model needs state_add and residual_x"):
        replace(model, error_names=("d1", "d2"))
    with pytest.raises(ValueError, match="expected only with error_names"):
        replace(model, state_add=lambda x, d: x + d)
    with pytest.raises(ValueError, match="model: 'pendulum' has no Jacobian G; ModelEKF needs one"):
        ModelEKF(replace(model, G=None), [0.0, 0.0], np.eye(2), 0.1)
    ModelUKF(replace(model, G=None), [0.0, 0.0], np.eye(2), 0.1)  # the UKF needs no Jacobian
    with pytest.raises(ValueError, match="LinearKF"):
        LinearKF(_additive_as_error_state(constant_velocity()), [0.0, 0.0], np.eye(2), 0.1)
    with pytest.raises(ValueError, match="error-state model; its own state_add and residual_x are used"):
        ModelUKF(_additive_as_error_state(model), [0.0, 0.0], np.eye(2), 0.1, residual_x=np.subtract)


def test_a_sensor_without_jacobian_serves_the_ukf_and_is_refused_by_the_ekf():
    model, sensor = pendulum()
    no_jacobian = replace(sensor, H=None)
    ukf = ModelUKF(model, [0.2, 0.0], np.eye(2) * 0.05, 0.05)
    ukf.update_sensor(no_jacobian, [0.25])
    with pytest.raises(ValueError, match="sensor: 'horiz' has no Jacobian H; ModelEKF needs one"):
        ModelEKF(model, [0.2, 0.0], np.eye(2) * 0.05, 0.05).update_sensor(no_jacobian, [0.25])


def test_covariance_stays_positive_definite_and_is_checked_where_it_enters():
    model = Model(("a",), (), g=lambda x, u, dt: x, G=lambda x, u, dt: np.eye(1), Q=lambda dt: 1e-6 * np.eye(1))
    precise = Sensor("a", ("a",), h=lambda x: x, H=lambda x: np.eye(1), R=[[1e-12]])
    ukf = ModelUKF(model, [0.0], [[1e12]], 0.1)  # a very uncertain state meets a very precise sensor
    ukf.update_sensor(precise, [1.0])
    assert np.linalg.eigvalsh(ukf.P).min() > 0
    ukf.predict()  # filterpy's Cholesky of the sigma points would fail on an indefinite P
    with pytest.raises(ValueError, match="P0: expected a positive definite covariance matrix, got smallest"):
        ModelEKF(model, [0.0], [[0.0]], 0.1)
    shrinking = replace(model, Q=lambda dt: (dt - 0.05) * np.eye(1), name="shrinking")
    f = ModelEKF(shrinking, [0.0], [[1.0]], 0.1)  # Q(0.1) is fine
    with pytest.raises(ValueError, match=r"shrinking.Q\(dt=0.01\): expected a positive semi-definite"):
        f.predict(dt=0.01)


def test_a_reset_on_a_sensor_blind_to_one_direction_keeps_the_covariance_sane():
    """Gravity cannot see a turn about itself: the reset must not invert the differences' noise in that
    direction (with numpy's default cutoff P grew to ~1e20 from this attitude)."""
    from quadlib.attitude.bias_model import attitude_bias_model
    from quadlib.geometry.quaternion import quat_from_euler
    from quadlib.sensors import gravity_sensor

    q0 = quat_from_euler(0.3, 0.2, 1.1)
    f = ModelEKF(attitude_bias_model(0.005, 1e-4), np.r_[q0, 0, 0, 0], np.diag([1e-4] * 3 + [1e-6] * 3), 0.01)
    truth = quat_from_euler(0.9, -0.2, 1.1)  # 40° of tilt away
    sensor = gravity_sensor(0.5)
    z = sensor.h(np.r_[truth, 0, 0, 0])
    f.inflate_toward(sensor, z, (0,))
    assert np.isfinite(f.P).all() and np.abs(f.P).max() < 10.0
    f.update_sensor(sensor, z)
    tilt_error = np.degrees(np.arccos(np.clip(sensor.h(f.estimate) @ z / 9.80665**2, -1, 1)))
    assert tilt_error < 10.0  # the reset lets the measurement pull the tilt most of the way


@pytest.mark.parametrize("cls", [LinearKF, ModelEKF, ModelUKF])
def test_input_noise_is_added_to_q_for_the_inputs_that_ask_for_it(cls):
    base = constant_velocity()
    extra = np.diag([0.0, 4.0])
    model = replace(base, input_noise=lambda u, dt: extra if abs(u[0]) > 10.0 else None)
    plain, noisy = cls(base, [0.0, 0.0], np.eye(2), 0.1), cls(model, [0.0, 0.0], np.eye(2), 0.1)
    for u in ([1.0], [20.0]):
        plain.predict(u)
        noisy.predict(u)
        expected = plain.P + (extra if u[0] > 10.0 else 0.0)
        np.testing.assert_allclose(noisy.P, expected, atol=1e-12)
        noisy.P = plain.P.copy()
    bad = cls(replace(base, input_noise=lambda u, dt: -np.eye(2)), [0.0, 0.0], np.eye(2), 0.1)
    with pytest.raises(ValueError, match=r"cv.input_noise\(u, dt=0.1\)"):
        bad.predict([0.0])


def test_an_uncorrected_state_keeps_its_value_and_the_covariance_is_joseph_with_that_gain():
    model = Model(("p", "v"), (), g=lambda x, u, dt: np.array([x[0] + dt * x[1], x[1]]),
                  G=lambda x, u, dt: np.array([[1.0, dt], [0.0, 1.0]]), B=lambda x, u, dt: np.zeros((2, 0)),
                  Q=lambda dt: 0.01 * np.eye(2))
    sensor = Sensor("pos", ("p",), h=lambda x: x[:1], H=lambda x: np.array([[1.0, 0.0]]), R=[[0.5]],
                    uncorrected=(1,))
    P0 = np.array([[2.0, 0.8], [0.8, 1.0]])
    ekf = ModelEKF(model, [0.0, 1.0], P0, 0.1)
    ekf.update_sensor(sensor, [3.0])
    H, R = np.array([[1.0, 0.0]]), np.array([[0.5]])
    K = P0 @ H.T / (H @ P0 @ H.T + R)
    K[1] = 0.0
    joseph = (np.eye(2) - K @ H) @ P0 @ (np.eye(2) - K @ H).T + K @ R @ K.T
    assert ekf.x[1, 0] == 1.0 and ekf.x[0, 0] == pytest.approx(3.0 * K[0, 0])
    np.testing.assert_allclose(ekf.P, joseph, atol=1e-12)
    assert ekf.P[1, 1] == pytest.approx(P0[1, 1])  # nothing was learnt about v
    for other in (LinearKF(model, [0.0, 1.0], P0, 0.1), ModelUKF(model, [0.0, 1.0], P0, 0.1)):
        with pytest.raises(ValueError, match="leaves states \\(1,\\) uncorrected, which"):
            other.update_sensor(sensor, [3.0])
    with pytest.raises(ValueError, match="uncorrected: expected indices below 2"):
        ModelEKF(model, [0.0, 1.0], P0, 0.1).update_sensor(Sensor("pos", ("p",), h=sensor.h, H=sensor.H, R=[[0.5]],
                                                                  uncorrected=(2,)), [3.0])
    with pytest.raises(ValueError, match="uncorrected: expected distinct state indices"):
        Sensor("pos", ("p",), h=sensor.h, H=sensor.H, R=[[0.5]], uncorrected=(1, 1))


def test_ukf_sigma_points_are_filterpys_default_bit_for_bit_and_bad_covariances_are_refused():
    """ModelUKF factors P with LAPACK's potrf directly; filterpy's default is scipy.linalg.cholesky."""
    from filterpy.kalman import MerweScaledSigmaPoints

    from quadlib.quad.quad3d import quad3d_model

    model = quad3d_model(0.3, 0.05)
    rng = np.random.default_rng(9)
    a = rng.normal(size=(7, 7))
    P = a @ a.T + 1e-6 * np.eye(7)
    ukf = ModelUKF(model, np.zeros(7), P, 0.01)
    default = MerweScaledSigmaPoints(7, alpha=0.5, beta=2.0, kappa=0.0)
    np.testing.assert_array_equal(ukf.points_fn.sigma_points(ukf.x, P), default.sigma_points(ukf.x, P))
    with pytest.raises(ValueError, match="P: expected a finite covariance"):
        ukf.points_fn.sigma_points(ukf.x, np.full((7, 7), np.nan))
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        ukf.points_fn.sigma_points(ukf.x, -np.eye(7))
