"""The 1D and 2D quadrotor models: Jacobians checked against finite differences, sympy and the
printed matrices of Tellex et al. §5–6, and the physics of the transition."""

import numpy as np
import pytest
import sympy as sp

from quadlib import LinearKF
from quadlib.constants import G0
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor


def central_difference(f, x, eps=1e-6):
    cols = [(f(x + eps * e) - f(x - eps * e)) / (2 * eps) for e in np.eye(x.size)]
    return np.array(cols).T


STATES_2D = [np.array(s) for s in ([0.0, 0.0, 1.0], [0.3, -1.2, 2.5], [-0.6, 2.0, -3.0], [1.2, 0.5, 4.9])]


@pytest.mark.parametrize("x", STATES_2D)
@pytest.mark.parametrize("variant", ["physics", "seed"])
def test_quad2d_jacobians_match_finite_differences(x, variant):
    model, sensor, u, dt = quad2d_model(0.1, 0.01, variant), quad2d_range_sensor(0.05), np.array([0.2]), 0.02
    np.testing.assert_allclose(model.G(x, u, dt), central_difference(lambda v: model.g(v, u, dt), x), atol=1e-8)
    np.testing.assert_allclose(sensor.H(x), central_difference(sensor.h, x), rtol=1e-6, atol=1e-8)


def quad2d_symbolic():
    phi, yd, y, u, dt, wall, g0 = sp.symbols("phi ydot y u dt wall g0", real=True)
    x = sp.Matrix([phi, yd, y])
    g_phys = sp.Matrix([u, yd + g0 * sp.tan(phi) * dt, y + yd * dt])
    g_seed = sp.Matrix([u, yd - sp.sin(phi) * dt, y + yd * dt])  # eq. (28) as printed
    h = sp.Matrix([(wall - y) / sp.cos(phi)])  # eq. (33)
    return (phi, yd, y, u, dt, wall, g0), x, g_phys, g_seed, h


def test_quad2d_jacobians_match_sympy_and_the_printed_eqs_31_and_35():
    (phi, yd, y, u, dt, wall, g0), x, g_phys, g_seed, h = quad2d_symbolic()
    printed_31 = sp.Matrix([[0, 0, 0], [-sp.cos(phi) * dt, 1, 0], [0, dt, 1]])
    printed_35 = sp.Matrix([[(wall - y) * sp.sin(phi) / sp.cos(phi) ** 2, 0, -1 / sp.cos(phi)]])
    assert sp.simplify(g_seed.jacobian(x) - printed_31) == sp.zeros(3, 3)  # eq. 31 is right for eq. 28
    assert sp.simplify(h.jacobian(x) - printed_35) == sp.zeros(1, 3)  # eq. 35 is right
    subs = {wall: 5.0, g0: G0, dt: 0.02, u: 0.2}
    G_sym = sp.lambdify((phi, yd, y), g_phys.jacobian(x).subs(subs))
    H_sym = sp.lambdify((phi, yd, y), h.jacobian(x).subs(subs))
    model, sensor = quad2d_model(0.1, 0.01), quad2d_range_sensor(0.05, wall_y_m=5.0)
    for s in STATES_2D:
        np.testing.assert_allclose(model.G(s, [0.2], 0.02), np.array(G_sym(*s), float), atol=1e-12)
        np.testing.assert_allclose(sensor.H(s), np.array(H_sym(*s), float), atol=1e-12)


def test_quad2d_printed_velocity_row_has_wrong_units_and_sign():
    # Erratum E9: eq. (28) adds sin(φ)·Δt [s] to a velocity [m/s]; the physical row is +g tan φ Δt.
    model, seed = quad2d_model(0.1, 0.01), quad2d_model(0.1, 0.01, "seed")
    x, dt = np.array([np.radians(10), 0.0, 0.0]), 1.0
    dv_phys, dv_seed = model.g(x, [x[0]], dt)[1], seed.g(x, [x[0]], dt)[1]
    assert dv_phys == pytest.approx(G0 * np.tan(np.radians(10)))  # ≈ +1.73 m/s after 1 s
    assert dv_seed == pytest.approx(-np.sin(np.radians(10)))  # −0.17: 10× too small, towards −y


def test_quad2d_range_grows_with_roll_and_shrinks_near_the_wall():
    sensor = quad2d_range_sensor(0.05, wall_y_m=5.0)
    assert sensor.h(np.array([0.0, 0.0, 2.0]))[0] == pytest.approx(3.0)
    assert sensor.h(np.array([np.pi / 3, 0.0, 2.0]))[0] == pytest.approx(6.0)  # 3 / cos 60°
    stack = np.array([[0.0, 0.0, 2.0], [np.pi / 3, 0.0, 2.0], [-np.pi / 3, 1.0, 4.0]])
    np.testing.assert_allclose(sensor.h(stack), [3.0, 6.0, 2.0])  # vectorised over rows
    assert sensor.h(stack[0]).shape == (1,)
    with pytest.raises(ValueError, match="lateral_accel: expected 'physics' or 'seed', got 'tan'"):
        quad2d_model(0.1, 0.01, "tan")


def test_quad1d_jacobians_match_sympy_finite_differences_and_eqs_14_17_25():
    zd, z, u, dt = sp.symbols("zdot z u dt", real=True)
    x = sp.Matrix([zd, z])
    g_printed_13 = sp.Matrix([z + u * dt, z + zd * dt])  # eq. (13) as printed
    g_matrix_14 = sp.Matrix([[1, 0], [dt, 1]]) * x + sp.Matrix([dt, 0]) * u  # eq. (14)
    assert sp.simplify(g_printed_13 - g_matrix_14) != sp.zeros(2, 1)  # erratum E8: (13) != (14)
    assert g_matrix_14.jacobian(x) == sp.Matrix([[1, 0], [dt, 1]])  # eq. (17)
    assert sp.Matrix([z]).jacobian(x) == sp.Matrix([[0, 1]])  # eq. (25)
    model, sensor = quad1d_model(0.5), quad1d_range_sensor(0.1)
    g_num = sp.lambdify((zd, z, u, dt), g_matrix_14)
    for s in ([0.0, 1.0], [-2.0, 7.5]):
        s = np.array(s)
        np.testing.assert_allclose(model.g(s, [0.3], 0.05), np.array(g_num(*s, 0.3, 0.05), float).ravel())
        np.testing.assert_allclose(model.G(s, [0.3], 0.05),
                                   central_difference(lambda v: model.g(v, [0.3], 0.05), s), atol=1e-9)
        np.testing.assert_allclose(sensor.H(s), central_difference(sensor.h, s), atol=1e-9)


def test_quad1d_is_linear_and_its_noise_is_a_held_acceleration():
    model = quad1d_model(0.5)
    LinearKF(model, [0.0, 1.0], np.eye(2), 0.02)  # refuses nonlinear models, so this checks g = G x + B u
    dt = 0.1
    Q = model.Q(dt)
    np.testing.assert_allclose(Q, 0.25 * np.array([[dt**2, dt**3 / 2], [dt**3 / 2, dt**4 / 4]]))
    assert np.linalg.matrix_rank(Q) == 1
    with pytest.raises(ValueError, match="accel_sigma_m_s2"):
        quad1d_model(-1.0)
