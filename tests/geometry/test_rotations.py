import numpy as np
import pytest
import sympy as sp
from scipy.spatial.transform import Rotation

from quadlib.geometry.quaternion import (
    body_rates_between,
    integrate_body_rate,
    quat_canonical,
    quat_conjugate,
    quat_from_euler,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_rotate,
    quat_to_dcm,
    quat_to_euler,
    quat_to_rotvec,
)
from quadlib.geometry.rotations import (
    accel_tilt,
    dcm_dyaw,
    dcm_to_euler,
    euler_rate_matrix,
    euler_to_dcm,
    mag_heading,
    wrap_angle,
)

rng = np.random.default_rng(7)
N = 200
EULER = np.column_stack([rng.uniform(-np.pi, np.pi, N), rng.uniform(-1.5, 1.5, N), rng.uniform(-np.pi, np.pi, N)])
EDGE = np.array([[0.0, 0.0, 0.0], [np.pi, 0.0, 0.0], [0.0, 0.0, np.pi], [0.3, np.pi / 2, 0.2], [0.3, -np.pi / 2, 0.2]])


def scipy_zyx(e):
    return Rotation.from_euler("ZYX", np.column_stack([e[:, 2], e[:, 1], e[:, 0]]))


def test_euler_to_dcm_is_eq_48_and_matches_scipy():
    for e in (EULER, EDGE):
        np.testing.assert_allclose(euler_to_dcm(*e.T), scipy_zyx(e).as_matrix(), atol=1e-12)
    # Tellex eq. (48) as printed, entry by entry
    phi, th, psi = sp.symbols("phi theta psi", real=True)
    c, s = sp.cos, sp.sin
    eq48 = sp.Matrix([
        [c(th) * c(psi), s(phi) * s(th) * c(psi) - c(phi) * s(psi), c(phi) * s(th) * c(psi) + s(phi) * s(psi)],
        [c(th) * s(psi), s(phi) * s(th) * s(psi) + c(phi) * c(psi), c(phi) * s(th) * s(psi) - s(phi) * c(psi)],
        [-s(th), c(th) * s(phi), c(th) * c(phi)]])
    f = sp.lambdify((phi, th, psi), eq48)
    for e in EULER[:20]:
        np.testing.assert_allclose(euler_to_dcm(*e), np.array(f(*e), dtype=float), atol=1e-12)


def test_dcm_dyaw_matches_eq_52_sympy_and_finite_differences():
    phi, th, psi = sp.symbols("phi theta psi", real=True)
    c, s = sp.cos, sp.sin
    eq52 = sp.Matrix([
        [-c(th) * s(psi), -s(phi) * s(th) * s(psi) - c(phi) * c(psi), -c(phi) * s(th) * s(psi) + s(phi) * c(psi)],
        [c(th) * c(psi), s(phi) * s(th) * c(psi) - c(phi) * s(psi), c(phi) * s(th) * c(psi) + s(phi) * s(psi)],
        [0, 0, 0]])
    f52 = sp.lambdify((phi, th, psi), eq52)
    eps = 1e-6
    for e in EULER[:20]:
        fd = (euler_to_dcm(e[0], e[1], e[2] + eps) - euler_to_dcm(e[0], e[1], e[2] - eps)) / (2 * eps)
        np.testing.assert_allclose(dcm_dyaw(*e), fd, atol=1e-9)
        np.testing.assert_allclose(dcm_dyaw(*e), np.array(f52(*e), dtype=float), atol=1e-12)


def test_dcm_to_euler_round_trip_and_wrap():
    back = np.column_stack(dcm_to_euler(euler_to_dcm(*EULER.T)))
    np.testing.assert_allclose(back, EULER, atol=1e-10)
    np.testing.assert_allclose(wrap_angle([np.pi, -np.pi, 3 * np.pi, 0.1 - 2 * np.pi]), [np.pi, np.pi, np.pi, 0.1])
    with pytest.raises(ValueError, match=r"R: expected shape \(..., 3, 3\), got \(3, 2\)"):
        dcm_to_euler(np.zeros((3, 2)))


def test_euler_rate_matrix_maps_body_rates_to_euler_rates():
    # finite differences of the Euler angles of R(t) with dR/dt = R [omega_b]x
    e, omega = np.array([0.4, -0.3, 1.0]), np.array([0.2, -0.5, 0.7])
    h = 1e-6
    R0 = euler_to_dcm(*e)
    plus = R0 @ Rotation.from_rotvec(omega * h).as_matrix()
    minus = R0 @ Rotation.from_rotvec(-omega * h).as_matrix()
    rates = (np.array(dcm_to_euler(plus)) - np.array(dcm_to_euler(minus))) / (2 * h)
    np.testing.assert_allclose(euler_rate_matrix(e[0], e[1]) @ omega, rates, atol=1e-7)
    np.testing.assert_allclose(euler_rate_matrix(0.0, 0.0), np.eye(3))  # near hover: W = I (eq. 39)


def test_accel_tilt_and_gravity_sign():
    g0 = 9.80665
    R = euler_to_dcm(*EULER[:, :2].T, 0.0)
    f_rest = -np.einsum("nji,j->ni", R, [0.0, 0.0, g0])  # f_b = R_nb^T (0 - g_n)
    roll, pitch = accel_tilt(f_rest)
    np.testing.assert_allclose(roll, EULER[:, 0], atol=1e-10)
    np.testing.assert_allclose(pitch, EULER[:, 1], atol=1e-10)
    np.testing.assert_allclose(accel_tilt([0.0, 0.0, -g0]), (0.0, 0.0))  # level: reads -g on z
    # the blog's roll: asin(A_y/|A|) has the wrong sign and is exact only at zero pitch
    blog_roll = np.arctan(f_rest[:, 1] / np.hypot(f_rest[:, 0], f_rest[:, 2]))
    level = np.abs(EULER[:, 1]) < 0.05
    small_roll = np.abs(EULER[:, 0]) < np.pi / 2
    np.testing.assert_allclose(blog_roll[level & small_roll], -EULER[level & small_roll, 0], atol=0.01)
    with pytest.raises(ValueError, match=r"f_b: expected shape \(..., 3\), got \(2,\)"):
        accel_tilt([0.0, 1.0])


def test_mag_heading_recovers_yaw_with_tilt_and_inclination():
    inclination = np.radians(60.0)
    m_n = 0.5 * np.array([np.cos(inclination), 0.0, np.sin(inclination)])  # north and down, gauss
    R = euler_to_dcm(*EULER.T)
    m_b = np.einsum("nji,j->ni", R, m_n)
    np.testing.assert_allclose(wrap_angle(mag_heading(m_b, EULER[:, 0], EULER[:, 1]) - EULER[:, 2]), 0.0, atol=1e-10)
    decl = np.radians(10.0)
    assert mag_heading(m_b[0], EULER[0, 0], EULER[0, 1], decl) == pytest.approx(wrap_angle(EULER[0, 2] + decl))


def test_quaternions_match_scipy_on_random_and_edge_inputs():
    for e in (EULER, EDGE):
        q = quat_from_euler(*e.T)
        ref = scipy_zyx(e)
        np.testing.assert_allclose(quat_canonical(q), quat_canonical(ref.as_quat(scalar_first=True)), atol=1e-12)
        np.testing.assert_allclose(quat_to_dcm(q), ref.as_matrix(), atol=1e-12)
        # round trip through Euler angles reproduces the rotation (also at gimbal lock)
        np.testing.assert_allclose(euler_to_dcm(*quat_to_euler(q)), ref.as_matrix(), atol=1e-12)
    q1, q2 = quat_from_euler(*EULER.T), quat_from_euler(*EULER[::-1].T)
    product = (Rotation.from_quat(q1, scalar_first=True) * Rotation.from_quat(q2, scalar_first=True))
    np.testing.assert_allclose(quat_canonical(quat_multiply(q1, q2)),
                               quat_canonical(product.as_quat(scalar_first=True)), atol=1e-12)
    v = rng.normal(size=(N, 3))
    np.testing.assert_allclose(quat_rotate(q1, v), Rotation.from_quat(q1, scalar_first=True).apply(v), atol=1e-12)
    np.testing.assert_allclose(quat_multiply(q1, quat_conjugate(q1)), np.tile([1.0, 0, 0, 0], (N, 1)), atol=1e-12)
    rv = np.vstack([rng.normal(size=(N, 3)), [[0.0, 0.0, 0.0], [1e-10, 0, 0], [np.pi, 0, 0]]])
    np.testing.assert_allclose(quat_canonical(quat_from_rotvec(rv)),
                               quat_canonical(Rotation.from_rotvec(rv).as_quat(scalar_first=True)), atol=1e-12)
    np.testing.assert_allclose(quat_to_rotvec(quat_from_rotvec(rv)), Rotation.from_rotvec(rv).as_rotvec(), atol=1e-10)
    np.testing.assert_allclose(quat_to_rotvec(-q1), Rotation.from_quat(q1, scalar_first=True).as_rotvec(), atol=1e-10)
    # q and -q are one rotation
    np.testing.assert_allclose(quat_to_dcm(-q1), quat_to_dcm(q1), atol=1e-15)
    with pytest.raises(ValueError, match="q: expected non-zero quaternions"):
        quat_normalize([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"p: expected shape \(..., 4\) scalar-first quaternions, got \(3,\)"):
        quat_multiply([1.0, 0.0, 0.0], q1[0])


def test_integrate_body_rate_multiplies_on_the_right():
    q0 = quat_from_euler(0.3, -0.2, 1.0)
    omega, dt = np.array([0.5, -1.0, 2.0]), 0.01
    q = q0
    for _ in range(100):
        q = integrate_body_rate(q, omega, dt)
    expected = Rotation.from_quat(q0, scalar_first=True) * Rotation.from_rotvec(omega * 1.0)
    np.testing.assert_allclose(quat_to_dcm(q), expected.as_matrix(), atol=1e-12)
    assert abs(np.linalg.norm(q) - 1.0) < 1e-12


def test_body_rates_between_inverts_the_gyro_step():
    omega = rng.normal(size=(50, 3))
    q = [quat_from_euler(0.1, 0.2, 0.3)]
    for w in omega[:-1]:
        q.append(integrate_body_rate(q[-1], w, 0.01))
    q = np.array(q)
    q[::3] *= -1  # the sign of a quaternion does not matter
    rates = body_rates_between(q, 0.01)
    np.testing.assert_allclose(rates[:-1], omega[:-1], atol=1e-9)
    np.testing.assert_allclose(rates[-1], rates[-2])


def test_helpers_refuse_or_flag_what_they_cannot_handle():
    from quadlib.geometry.quaternion import quat_from_dcm, quat_normalize, quat_to_dcm, quat_to_euler
    from quadlib.geometry.rotations import accel_tilt

    np.testing.assert_allclose(quat_normalize([1e154] * 4), [0.5] * 4)  # no overflow to zeros
    np.testing.assert_allclose(quat_normalize([1e-170, 0, 0, 0]), [1.0, 0, 0, 0])  # no underflow
    with pytest.raises(ValueError, match="q: expected non-zero quaternions, got one with norm 0"):
        quat_normalize([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match=r"q: expected unit quaternions \(\|norm − 1\| ≤ 1e-06\), got norm 0;"):
        quat_to_dcm([0.0, 0.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="got norm 0.707107; normalise first"):
        quat_to_euler([0.5, 0.5, 0.0, 0.0])
    reflection = np.diag([1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"R: expected rotation matrices .* determinant -1 \(a reflection\)"):
        quat_from_dcm(reflection)
    with pytest.raises(ValueError, match=r"max \|RᵀR − I\| = 3 and determinant 8"):
        quat_from_dcm(2 * np.eye(3))
    roll, pitch = accel_tilt([[0.01, -0.02, 0.03], [0.0, 0.0, -9.8], [np.nan] * 3])  # free fall, level, missing
    assert np.isnan(roll[[0, 2]]).all() and np.isnan(pitch[[0, 2]]).all()
    assert roll[1] == 0.0 and pitch[1] == 0.0
