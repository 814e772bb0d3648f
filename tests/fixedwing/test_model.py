"""Salmony's fixed-wing model: Jacobians, and the printed equations' errors (E18-E21)."""

import numpy as np
import pytest
import sympy as sp

from quadlib.fixedwing.model import (
    accel_jacobian,
    accel_model,
    airspeed_from_pressure,
    fixedwing_A,
    fixedwing_accel_sensor,
    fixedwing_f,
    fixedwing_mag_sensor,
    lowpass2,
    mag_jacobian,
    mag_model,
)
from quadlib.geometry.quaternion import integrate_body_rate, quat_from_euler

X = np.r_[quat_from_euler(0.2, -0.15, 1.1), 0.01, -0.02, 0.015]
W = np.array([0.3, -0.2, 0.25])
q0, q1, q2, q3, bp, bq, br, p, q, r, Va, g, d = sp.symbols("q0 q1 q2 q3 b_p b_q b_r p q r V_a g delta_m", real=True)
XS = sp.Matrix([q0, q1, q2, q3, bp, bq, br])
VALUES = dict(zip([q0, q1, q2, q3, bp, bq, br, p, q, r, Va, g, d], [*X, *W, 20.0, 9.80665, 0.2], strict=True))


def _fd(fun, x, eps=1e-7):
    return np.column_stack([(fun(x + eps * e) - fun(x - eps * e)) / (2 * eps) for e in np.eye(len(x))])


def test_jacobians_match_finite_differences():
    np.testing.assert_allclose(fixedwing_A(X, W), _fd(lambda x: fixedwing_f(x, W), X), atol=1e-8)
    np.testing.assert_allclose(accel_jacobian(X, W, 20.0), _fd(lambda x: accel_model(x, W, 20.0), X), atol=1e-6)
    np.testing.assert_allclose(mag_jacobian(X, 0.2, 0.9), _fd(lambda x: mag_model(x, 0.2, 0.9), X), atol=1e-8)


def test_the_sensors_evaluate_the_models_off_the_unit_sphere_too():
    x = X * np.r_[[1.1] * 4, [1.0] * 3]  # the Jacobians are those of quat_to_dcm's form, |q| = 1.1 included
    accel, no_airspeed = fixedwing_accel_sensor(0.1), fixedwing_accel_sensor(0.1, unmodelled_m_s2=3.0)
    mag = fixedwing_mag_sensor(0.2, 0.01, 0.9)
    np.testing.assert_allclose(accel.h(X, np.r_[W, 20.0]), accel_model(X, W, 20.0), atol=1e-15)
    np.testing.assert_allclose(no_airspeed.h(X, W), accel_model(X, W, 0.0), atol=1e-15)
    np.testing.assert_allclose(mag.h(X), mag_model(X, 0.2, 0.9), atol=1e-15)
    np.testing.assert_allclose(accel.H(x, np.r_[W, 20.0]), _fd(lambda v: accel.h(v, np.r_[W, 20.0]), x), atol=1e-6)
    np.testing.assert_allclose(mag.H(x), _fd(mag.h, x), atol=1e-8)


def test_kinematics_integrate_to_the_exact_rotation():
    x, dt = X.copy(), 1e-4
    for _ in range(1000):  # 0.1 s of Euler steps of eq. (9)
        x = x + dt * fixedwing_f(x, W)
    exact = integrate_body_rate(X[:4], W - X[4:], 0.1)
    np.testing.assert_allclose(x[:4] / np.linalg.norm(x[:4]), exact, atol=1e-6)


def test_eq_10_11_apply_one_half_twice():
    Xi_printed = sp.Rational(1, 2) * sp.Matrix([[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]])
    printed = sp.Rational(1, 2) * Xi_printed * sp.Matrix([p - bp, q - bq, r - br])  # eq. (10) with eq. (11)
    ours = fixedwing_f(X, W)[:4]
    np.testing.assert_allclose(np.array(printed.subs(VALUES), dtype=float).ravel(), 0.5 * ours, atol=1e-15)


def test_eq_12_has_one_wrong_entry():
    f = sp.Matrix.vstack(sp.Rational(1, 2) * sp.Matrix([[-q1, -q2, -q3], [q0, -q3, q2], [q3, q0, -q1], [-q2, q1, q0]])
                         * sp.Matrix([p - bp, q - bq, r - br]), sp.zeros(3, 1))
    printed = sp.Rational(1, 2) * sp.Matrix([
        [0, -(p - bp), -(q - bq), -(r - br), q1, q2, q3], [p - bp, 0, r - br, -(q - bq), -q0, q3, -q2],
        [q - bq, -(r - br), 0, p - bp, -q3, -q0, q1], [r - br, q - bq, -(p - bp), 0, q2, -q1, q0],
        [0] * 7, [0] * 7, [0] * 7])
    diff = sp.simplify(f.jacobian(XS) - printed)
    assert [(i, j) for i in range(7) for j in range(7) if diff[i, j] != 0] == [(3, 6)]
    assert sp.simplify(diff[3, 6] + q0) == 0  # printed +q0/2, derivative -q0/2
    np.testing.assert_allclose(fixedwing_A(X, W), np.array(f.jacobian(XS).subs(VALUES), dtype=float), atol=1e-15)


def test_eq_13_is_right_and_eq_14_has_a_sign_error_the_printed_C_does_not():
    acc13 = sp.Matrix([0, Va * (r - br), -Va * (q - bq)]) - g * sp.Matrix(
        [2 * (q1 * q3 - q2 * q0), 2 * (q2 * q3 + q1 * q0), 1 - 2 * (q1**2 + q2**2)])
    np.testing.assert_allclose(accel_model(X, W, 20.0), np.array(acc13.subs(VALUES), dtype=float).ravel(), atol=1e-12)
    mag14 = sp.Matrix([2 * sp.sin(d) * (q0 * q3 + q1 * q2) - sp.cos(d) * (2 * q2**2 + 2 * q3**2 - 1),
                       -2 * sp.cos(d) * (q0 * q3 + q1 * q2) - sp.sin(d) * (2 * q1**2 + 2 * q3**2 - 1),
                       2 * sp.cos(d) * (q0 * q2 + q1 * q3) - 2 * sp.sin(d) * (q0 * q1 - q2 * q3)])
    ours = mag_model(X, 0.2)
    printed = np.array(mag14.subs(VALUES), dtype=float).ravel()
    np.testing.assert_allclose(ours[[0, 2]], printed[[0, 2]], atol=1e-12)
    assert ours[1] - printed[1] == pytest.approx(4 * X[1] * X[2] * np.cos(0.2))  # the q1 q2 term's sign
    C_mag_printed = sp.Matrix([
        [2 * q3 * sp.sin(d), 2 * q2 * sp.sin(d), 2 * (q1 * sp.sin(d) - 2 * q2 * sp.cos(d)),
         2 * (q0 * sp.sin(d) - 2 * q3 * sp.cos(d)), 0, 0, 0],
        [-2 * q3 * sp.cos(d), 2 * (q2 * sp.cos(d) - 2 * q1 * sp.sin(d)), 2 * q1 * sp.cos(d),
         -2 * (q0 * sp.cos(d) + 2 * q3 * sp.sin(d)), 0, 0, 0],
        [2 * (q2 * sp.cos(d) - q1 * sp.sin(d)), 2 * (q3 * sp.cos(d) - q0 * sp.sin(d)),
         2 * (q0 * sp.cos(d) + q3 * sp.sin(d)), 2 * (q1 * sp.cos(d) + q2 * sp.sin(d)), 0, 0, 0]])
    np.testing.assert_allclose(mag_jacobian(X, 0.2), np.array(C_mag_printed.subs(VALUES), dtype=float), atol=1e-12)
    C_acc_printed = sp.Matrix([[2 * g * q2, -2 * g * q3, 2 * g * q0, -2 * g * q1, 0, 0, 0],
                               [-2 * g * q1, -2 * g * q0, -2 * g * q3, -2 * g * q2, 0, 0, -Va],
                               [0, 4 * g * q1, 4 * g * q2, 0, 0, Va, 0]])
    np.testing.assert_allclose(accel_jacobian(X, W, 20.0), np.array(C_acc_printed.subs(VALUES), dtype=float),
                               atol=1e-12)


def test_lowpass_is_eq_8_and_passes_a_constant():
    np.testing.assert_allclose(lowpass2(np.full(50, 3.0), 2.0, 0.01), 3.0)
    step = lowpass2(np.r_[np.zeros(1), np.ones(400)], 2.0, 0.001)
    wt = 2 * np.pi * 2.0 * 0.001
    assert step[1] == pytest.approx(wt**2 / (1 + 2 * wt + wt**2))
    # critically damped, 2 Hz: the continuous step response 1 - (1 + w t) e^{-w t} at t = 0.1 s
    w = 2 * np.pi * 2.0
    assert step[100] == pytest.approx(1 - (1 + w * 0.1) * np.exp(-w * 0.1), abs=0.01)
    assert np.all(np.diff(step) >= -1e-15)  # no overshoot


def test_pitot_airspeed():
    assert airspeed_from_pressure(245.0) == pytest.approx(20.0, rel=1e-3)
    with pytest.raises(ValueError, match="dp_pa: expected non-negative"):
        airspeed_from_pressure([-1.0])


@pytest.mark.parametrize("model", [lambda x: accel_model(x, W, 20.0), lambda x: mag_model(x, 0.2)])
def test_the_models_refuse_a_quaternion_that_is_not_a_rotation(model):
    with pytest.raises(ValueError, match=r"x\[:4\]: expected unit quaternions"):
        model(X * np.r_[[1.2] * 4, [1.0] * 3])
