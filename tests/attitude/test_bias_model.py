"""The shared attitude-and-gyro-bias error-state model: its Jacobians against finite differences."""

import numpy as np
import pytest

from quadlib.attitude.bias_model import (
    attitude_bias_model,
    gyro_step,
    gyro_step_jacobian,
    normalize_attitude,
    normalize_attitude_jacobian,
)
from quadlib.geometry.quaternion import quat_canonical


@pytest.mark.parametrize("rate", [np.array([0.4, -0.3, 0.8]), np.array([0.02 + 1e-9, -0.01, 0.03])])
def test_error_state_model_jacobians_match_finite_differences(rate):
    model = attitude_bias_model(0.005, 1e-4)
    rng = np.random.default_rng(3)
    x = np.r_[quat_canonical(rng.normal(size=4) / 2.0), 0.02, -0.01, 0.03]
    x[:4] /= np.linalg.norm(x[:4])
    u, dt, eps = rate, 0.05, 1e-6  # the second rate minus the bias is nearly zero: the series branch
    step = lambda e: model.residual_x(model.g(model.state_add(x, e), u, dt), model.g(x, u, dt))  # noqa: E731
    G_fd = np.column_stack([(step(eps * e) - step(-eps * e)) / (2 * eps) for e in np.eye(6)])
    np.testing.assert_allclose(model.G(x, u, dt), G_fd, atol=1e-8)
    add_fd = np.column_stack([(model.state_add(x, eps * e) - model.state_add(x, -eps * e)) / (2 * eps)
                              for e in np.eye(6)])
    np.testing.assert_allclose(model.add_jacobian(x), add_fd, atol=1e-8)
    e = rng.normal(size=6) * 0.1
    np.testing.assert_allclose(model.residual_x(model.state_add(x, e), x), e, atol=1e-12)  # ⊟ inverts ⊞


def test_the_normalisation_jacobian_removes_the_radial_direction():
    x = np.r_[1.2 * quat_canonical(np.array([0.9, 0.1, -0.3, 0.3])), 0.01, 0.0, 0.0]
    eps = 1e-7
    fd = np.column_stack([(normalize_attitude(x + eps * e) - normalize_attitude(x - eps * e)) / (2 * eps)
                          for e in np.eye(7)])
    np.testing.assert_allclose(normalize_attitude_jacobian(x), fd, atol=1e-7)


@pytest.mark.parametrize("angle", [0.0, 1e-7, 1e-4, 2e-3, 0.3, 2.5])
def test_the_exact_gyro_step_jacobian_matches_finite_differences(angle):
    rng = np.random.default_rng(5)
    x = np.r_[quat_canonical(rng.normal(size=4)), 0.02, -0.01, 0.03]
    x[:4] /= np.linalg.norm(x[:4])
    dt = 0.02
    axis = np.array([0.6, -0.48, 0.64])
    u = x[4:] + angle / dt * axis  # the step turns by `angle`: each branch of the series
    eps = 1e-6
    fd = np.column_stack([(gyro_step(x + eps * e, u, dt) - gyro_step(x - eps * e, u, dt)) / (2 * eps)
                          for e in np.eye(7)])
    np.testing.assert_allclose(gyro_step_jacobian(x, u, dt), fd, atol=1e-8)
