import numpy as np
import pytest
import sympy as sp

from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter, vector_jacobian
from quadlib.attitude.tumble import attitude_samples, random_rotation
from quadlib.geometry.quaternion import quat_conjugate, quat_multiply, quat_to_rotvec

NOISE = AttitudeNoise()
T, Q_TRUE, OMEGA = random_rotation(6.0, NOISE, np.random.default_rng(3))


def _error_deg(est):
    return np.degrees(np.linalg.norm(quat_to_rotvec(quat_multiply(quat_conjugate(Q_TRUE), est)), axis=1))


def test_qkf_jacobian_is_eq_2_54():
    x1, x2, x3, x4, a3, m1, m3 = sp.symbols("x1 x2 x3 x4 a3 m1 m3", real=True)
    eq254 = 2 * sp.Matrix([
        [-a3 * x3, a3 * x4, -a3 * x1, a3 * x2], [a3 * x2, a3 * x1, a3 * x4, a3 * x3],
        [a3 * x1, -a3 * x2, -a3 * x3, a3 * x4],
        [m1 * x1 - m3 * x3, m1 * x2 + m3 * x4, -m1 * x3 - m3 * x1, m3 * x2 - m1 * x4],
        [m3 * x2 - m1 * x4, m1 * x3 + m3 * x1, m1 * x2 + m3 * x4, m3 * x3 - m1 * x1],
        [m1 * x3 + m3 * x1, m1 * x4 - m3 * x2, m1 * x1 - m3 * x3, m1 * x2 + m3 * x4]])
    q = np.array([0.8, -0.3, 0.4, 0.33])
    q /= np.linalg.norm(q)
    a_n, m_n = np.array([0.0, 0.0, -9.8]), np.array([0.2, 0.0, 0.45])
    ours = np.vstack([vector_jacobian(q, a_n), vector_jacobian(q, m_n)])
    printed = np.array(eq254.subs({x1: q[0], x2: q[1], x3: q[2], x4: q[3], a3: a_n[2], m1: m_n[0], m3: m_n[2]}),
                       dtype=float)
    np.testing.assert_allclose(ours, printed, atol=1e-12)


@pytest.mark.parametrize("name", list(FILTERS))
def test_every_filter_converges_and_keeps_a_unit_quaternion(name):
    g, a, m = attitude_samples(Q_TRUE, OMEGA, NOISE, np.random.default_rng(4), mag_every=5)
    est = run_attitude_filter(FILTERS[name](NOISE), g, a, m)
    assert _error_deg(est)[T > 2.0].max() < 1.0  # from the identity to under a degree
    assert np.abs(np.linalg.norm(est, axis=1) - 1.0).max() < 1e-9


@pytest.mark.parametrize("name", list(FILTERS))
def test_magnetometer_outage_and_free_fall_are_ridden_through(name):
    g, a, m = attitude_samples(Q_TRUE, OMEGA, NOISE, np.random.default_rng(5))
    outage = (T > 2.0) & (T < 3.0)
    fall = (T > 4.0) & (T < 4.5)
    m[outage] = np.nan
    a[fall] = np.random.default_rng(6).normal(0.0, NOISE.sigma_accel, (fall.sum(), 3))  # free fall reads ~0
    est = run_attitude_filter(FILTERS[name](NOISE), g, a, m)
    err = _error_deg(est)
    assert np.all(np.isfinite(est))
    assert err[T > 1.5].max() < 1.5  # the gyro carries the attitude through both
    assert np.abs(np.linalg.norm(est, axis=1) - 1.0).max() < 1e-9


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="noise: expected an AttitudeNoise, got dict"):
        FILTERS["QF"]({})
    with pytest.raises(ValueError, match=r"gyro, accel, mag: expected three \(N, 3\) arrays"):
        run_attitude_filter(FILTERS["QF"](NOISE), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((2, 3)))
