import numpy as np
import pytest
import sympy as sp

from quadlib.constants import G0
from quadlib.geometry.rotations import wrap_angle
from quadlib.quad.flight import figure_eight
from quadlib.quad.quad3d import (
    imu_inputs,
    quad3d_gps_sensor,
    quad3d_mag_sensor,
    quad3d_model,
    quad3d_ukf_options,
)

MODEL = quad3d_model(0.5, 0.05)
X = np.array([1.0, -2.0, -3.0, 0.5, -0.3, 0.1, 2.5])
U = np.array([0.8, -0.4, -9.5, 0.3, 0.2, -0.15])


def test_jacobian_matches_finite_differences_and_sympy_eq_51():
    dt, eps = 0.01, 1e-6
    fd = np.array([(MODEL.g(X + eps * e, U, dt) - MODEL.g(X - eps * e, U, dt)) / (2 * eps) for e in np.eye(7)]).T
    np.testing.assert_allclose(MODEL.G(X, U, dt), fd, atol=1e-8)
    # sympy: the velocity rows of eq. (49) differentiated with respect to yaw
    phi, th, psi, dts = sp.symbols("phi theta psi Delta_t", real=True)
    f = sp.Matrix(sp.symbols("f_x f_y f_z", real=True))
    Rz = sp.Matrix([[sp.cos(psi), -sp.sin(psi), 0], [sp.sin(psi), sp.cos(psi), 0], [0, 0, 1]])
    Ry = sp.Matrix([[sp.cos(th), 0, sp.sin(th)], [0, 1, 0], [-sp.sin(th), 0, sp.cos(th)]])
    Rx = sp.Matrix([[1, 0, 0], [0, sp.cos(phi), -sp.sin(phi)], [0, sp.sin(phi), sp.cos(phi)]])
    column = sp.diff(Rz * Ry * Rx * f * dts, psi)
    values = {phi: U[4], th: U[5], psi: X[6], dts: dt, f[0]: U[0], f[1]: U[1], f[2]: U[2]}
    np.testing.assert_allclose(MODEL.G(X, U, dt)[3:6, 6], np.array(column.subs(values), dtype=float).ravel(),
                               atol=1e-12)


def test_gravity_sign_hover_stays_put_and_the_printed_sign_does_not():
    hover_u = np.array([0.0, 0.0, -G0, 0.0, 0.0, 0.0])  # level accelerometer at rest
    x = np.array([0.0, 0.0, -3.0, 0.0, 0.0, 0.0, 0.4])
    np.testing.assert_allclose(MODEL.g(x, hover_u, 0.01), x, atol=1e-15)
    seed = quad3d_model(0.5, 0.05, gravity="seed").g(x, hover_u, 0.01)
    assert seed[5] == pytest.approx(-2 * G0 * 0.01)  # climbs at 2 g
    with pytest.raises(ValueError, match="gravity: expected 'ned' or 'seed', got 'up'"):
        quad3d_model(0.5, 0.05, gravity="up")


def test_yaw_wraps_in_the_model_the_mag_residual_and_the_ukf_mean():
    x = X.copy()
    x[6] = np.pi - 0.01
    u = U.copy()
    u[3] = 2.0
    assert MODEL.g(x, u, 0.01)[6] == pytest.approx(-np.pi + 0.01)
    mag = quad3d_mag_sensor(0.1)
    assert mag.residual(np.array([-np.pi + 0.01]), np.array([np.pi - 0.01]))[0] == pytest.approx(0.02)
    opts = quad3d_ukf_options()
    sigmas = np.tile(X, (3, 1))
    sigmas[:, 6] = [np.pi - 0.05, -np.pi + 0.05, np.pi]
    mean = opts["x_mean_fn"](sigmas, np.array([0.25, 0.25, 0.5]))
    assert abs(wrap_angle(mean[6] - np.pi)) < 1e-12
    assert opts["residual_x"](sigmas[1], sigmas[0])[6] == pytest.approx(0.1)
    gps = quad3d_gps_sensor()
    np.testing.assert_allclose(gps.H(X) @ X, X[:6])


def test_dead_reckoning_with_exact_inputs_follows_the_truth():
    fl = figure_eight(duration_s=4.0, rate_hz=500.0)
    u = imu_inputs(fl.dt, fl.f_b, fl.omega_b, fl.euler[:, :2], decimate=5)
    x = np.concatenate([fl.pos[0], fl.vel[0], fl.euler[:1, 2]])
    dt = 5 * fl.dt
    for k in range(u.shape[0] - 1):
        x = MODEL.g(x, u[k], dt)
    k_end = 5 * (u.shape[0] - 1)
    assert np.linalg.norm(x[:3] - fl.pos[k_end]) < 0.05  # m, after 4 s of pure integration
    assert np.linalg.norm(x[3:6] - fl.vel[k_end]) < 0.05
    assert abs(wrap_angle(x[6] - fl.euler[k_end, 2])) < 0.01
    with pytest.raises(ValueError, match=r"decimate: expected an int in \[1, 2001\], got 0"):
        imu_inputs(fl.dt, fl.f_b, fl.omega_b, fl.euler[:, :2], decimate=0)
