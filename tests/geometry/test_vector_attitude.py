import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from quadlib.geometry.quaternion import (
    integrate_body_rate,
    integrate_body_rate_linear,
    quat_canonical,
    quat_conjugate,
    quat_from_dcm,
    quat_from_rotvec,
    quat_multiply,
    quat_to_rotvec,
)
from quadlib.geometry.vector_attitude import (
    attitude_from_accel_mag,
    average_geodesic,
    average_quaternion,
    average_rotvec,
)

G_N = np.array([0.0, 0.0, 9.80665])
M_N = 0.5 * np.array([np.cos(np.radians(60)), 0.0, np.sin(np.radians(60))])


def _angle(q1, q2):
    return np.linalg.norm(quat_to_rotvec(quat_multiply(quat_conjugate(q1), q2)), axis=-1)


def test_quat_from_dcm_matches_scipy_including_half_turns():
    r = Rotation.concatenate([Rotation.random(500, random_state=3),
                              Rotation.from_rotvec(np.pi * np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]])
                                                   / np.linalg.norm([[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]],
                                                                    axis=1, keepdims=True))])
    q = quat_from_dcm(r.as_matrix())
    ref = r.as_quat(scalar_first=True)
    assert np.all(np.minimum(np.abs(q - ref).max(axis=1), np.abs(q + ref).max(axis=1)) < 1e-12)


def test_linearised_gyro_step_is_first_order_and_leaves_the_unit_sphere():
    q0 = quat_from_rotvec([0.3, -0.2, 0.5])
    omega = np.array([1.0, -2.0, 0.5])
    for dt in (0.01, 0.001):
        exact, lin = integrate_body_rate(q0, omega, dt), integrate_body_rate_linear(q0, omega, dt)
        assert np.linalg.norm(lin) == pytest.approx(np.sqrt(1 + (np.linalg.norm(omega) * dt / 2) ** 2), rel=1e-12)
        assert np.abs(lin / np.linalg.norm(lin) - exact).max() < (np.linalg.norm(omega) * dt) ** 3


def test_absolute_attitude_recovers_random_attitudes():
    r = Rotation.random(300, random_state=5)
    R = r.as_matrix()
    f_b = -np.einsum("nji,j->ni", R, G_N)
    m_b = np.einsum("nji,j->ni", R, M_N)
    att = attitude_from_accel_mag(f_b, m_b)
    assert att.valid.all()
    np.testing.assert_allclose(quat_canonical(att.q_nb), quat_canonical(r.as_quat(scalar_first=True)), atol=1e-12)


def test_free_fall_and_parallel_vectors_hold_the_last_attitude_and_are_flagged():
    q_true = Rotation.from_euler("ZYX", [0.4, 0.1, -0.2])
    R = q_true.as_matrix()
    f_ok, m_ok = -R.T @ G_N, R.T @ M_N
    f_b = np.array([f_ok * 0.0 + 0.1, f_ok, f_ok * 0.05, f_ok, f_ok])  # first: free fall before any valid sample
    m_b = np.array([m_ok, m_ok, m_ok, -f_ok / 20.0, m_ok])  # fourth: field along gravity
    att = attitude_from_accel_mag(f_b, m_b)
    np.testing.assert_array_equal(att.valid, [False, True, False, False, True])
    np.testing.assert_allclose(att.q_nb[0], [1.0, 0.0, 0.0, 0.0])  # nothing to hold yet
    for k in (2, 3):  # held, not NaN, not garbage
        np.testing.assert_allclose(att.q_nb[k], att.q_nb[1])
    with pytest.raises(ValueError, match=r"f_b, m_b: expected two \(N, 3\) arrays"):
        attitude_from_accel_mag(f_b, m_b[:2])


def test_geodesic_average_splits_the_shortest_rotation_by_the_weights():
    rng = np.random.default_rng(2)
    q1 = quat_from_rotvec(rng.normal(size=(200, 3)))
    q2 = quat_multiply(q1, quat_from_rotvec(rng.normal(size=(200, 3)) * 0.8))
    w2 = rng.uniform(0, 1, 200)
    avg = average_geodesic(q1, q2, 1 - w2, w2)
    total = _angle(q1, q2)
    np.testing.assert_allclose(_angle(q1, avg), w2 * total, atol=1e-10)
    np.testing.assert_allclose(_angle(avg, q2), (1 - w2) * total, atol=1e-10)
    # with equal weights, the renormalised quaternion mean is the same point (same hemisphere)
    same = np.sum(q1 * q2, axis=1) > 0
    np.testing.assert_allclose(quat_canonical(average_quaternion(q1[same], q2[same])),
                               quat_canonical(average_geodesic(q1[same], q2[same])), atol=1e-12)
    # but not with unequal weights, and q vs -q averages to nothing
    lerp = average_quaternion(q1[same], q2[same], 0.9, 0.1)
    assert np.abs(_angle(lerp, average_geodesic(q1[same], q2[same], 0.9, 0.1))).max() > 1e-4
    with pytest.raises(ValueError, match="q: expected non-zero quaternions"):
        average_quaternion(q1[0], -q1[0])


def test_rotvec_average_is_exact_only_for_parallel_vectors():
    axis = np.array([0.0, 0.6, 0.8])
    exact = average_rotvec(0.2 * axis, 1.0 * axis, 0.5, 0.5)
    np.testing.assert_allclose(exact, 0.6 * axis)
    q_a, q_b = quat_from_rotvec([1.0, 0.0, 0.0]), quat_from_rotvec([0.0, 1.0, 0.0])
    naive = quat_from_rotvec(average_rotvec([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]))
    assert _angle(naive, average_geodesic(q_a, q_b)) > 0.01
    with pytest.raises(ValueError, match="w1, w2: expected non-negative weights"):
        average_rotvec(axis, axis, -1.0, 0.5)
