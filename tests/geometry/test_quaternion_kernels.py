"""The unchecked one-quaternion kernels compute what their checked namesakes compute."""

import numpy as np

from quadlib.attitude.bias_model import quaternion_rate_matrix
from quadlib.geometry import euler_to_dcm
from quadlib.geometry.quaternion import (
    quat_conjugate,
    quat_from_dcm,
    quat_from_euler,
    quat_from_rotvec,
    quat_multiply,
    quat_normalize,
    quat_to_dcm,
    quat_to_euler,
    quat_to_rotvec,
    vector_jacobian,
)
from quadlib.kernels import quaternion as kernels

RNG = np.random.default_rng(11)
CASES = [(RNG.normal(size=4), RNG.normal(size=4), RNG.normal(size=3) * s) for s in (1e-10, 1e-4, 0.3, 3.0) * 5]


def test_each_kernel_equals_its_checked_namesake():
    for p, q, v in CASES:
        np.testing.assert_allclose(kernels.multiply(p, q), quat_multiply(p, q), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.exp_rotvec(v), quat_from_rotvec(v), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.normalize(q), quat_normalize(q), rtol=0, atol=1e-15)
        u = quat_normalize(q)
        np.testing.assert_allclose(kernels.dcm(u), quat_to_dcm(u), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.rotvec(u), quat_to_rotvec(u), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.rotvec(kernels.exp_rotvec(v)), quat_to_rotvec(quat_from_rotvec(v)), rtol=0,
                                   atol=1e-15)
        np.testing.assert_array_equal(kernels.conjugate(q), quat_conjugate(q))
        np.testing.assert_allclose(kernels.from_dcm(quat_to_dcm(u)), quat_from_dcm(quat_to_dcm(u)), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.euler_dcm(*v), euler_to_dcm(*v), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.skew(v) @ q[1:], np.cross(v, q[1:]), rtol=0, atol=1e-15)
        np.testing.assert_allclose(kernels.rate_matrix(q), quaternion_rate_matrix(q), rtol=0, atol=0)
        J = np.reshape(kernels.body_vector_jacobian(q, v), (3, 4))  # its entries row by row
        np.testing.assert_allclose(J, vector_jacobian(q, v), rtol=1e-12, atol=1e-12 * np.abs(v).max())


def test_euler_kernels_equal_their_checked_namesakes_including_gimbal_lock():
    for _, q, v in CASES:
        np.testing.assert_allclose(kernels.from_euler(*v), quat_from_euler(*v), rtol=0, atol=1e-15)
        u = quat_normalize(q)
        np.testing.assert_allclose(kernels.to_euler(u), quat_to_euler(u), rtol=0, atol=1e-15)
    for pitch in (np.pi / 2, -np.pi / 2):  # roll and yaw not separable: both give roll 0
        locked = quat_from_euler(0.3, pitch, -0.7)
        np.testing.assert_allclose(kernels.to_euler(locked), quat_to_euler(locked), rtol=0, atol=1e-15)
        assert kernels.to_euler(locked)[0] == 0.0
