"""A Kernel called from Python: the field's own signature, one compiled version whatever the arrays."""

import numpy as np
import pytest

from quadlib.engine import Kernel
from quadlib.imu import untrusted_gyro_noise
from quadlib.kernels import attitude as attitude_maths
from quadlib.sensors import gravity_sensor, heading_sensor


def test_a_sensor_kernel_takes_h_of_x_or_h_of_x_and_its_context():
    x = np.r_[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    np.testing.assert_allclose(gravity_sensor(0.3).h(x), [0.0, 0.0, -9.80665])
    np.testing.assert_allclose(heading_sensor(0.1).h(x, np.array([0.0, 1.0, 0.5])), [np.pi / 2])
    with pytest.raises(TypeError, match="h\\(x\\)"):
        gravity_sensor(0.3).h(x, np.zeros(3))


def test_input_noise_is_none_until_the_gyro_clips():
    noise = untrusted_gyro_noise(2.0, [1.0, 1.0, 1.0, 0.0])
    assert noise(np.array([0.5, 0.0, 0.0]), 0.01) is None
    np.testing.assert_allclose(np.diag(noise(np.array([2.0, 0.0, 0.0]), 0.01)), [4e-4, 4e-4, 4e-4, 0.0])


def test_a_view_a_read_only_array_or_a_list_reuse_the_kernels_one_compiled_version():
    body = Kernel("h", attitude_maths.body_vector, [0.0, 0.0, -9.80665])
    x = np.r_[0.9, 0.1, -0.3, 0.2, 0.0, 0.0, 0.0]
    expected = body(x)
    versions = len(attitude_maths.body_vector.signatures)
    frozen = x.copy()
    frozen.setflags(write=False)
    wide = np.vstack([x, x]).T  # a column of it is a strided view
    for v in (frozen, wide[:, 0], x.tolist()):
        np.testing.assert_array_equal(body(v), expected)
    np.testing.assert_allclose(body(x.astype(np.float32)), expected, rtol=1e-6)
    assert len(attitude_maths.body_vector.signatures) == versions
    assert not frozen.flags.writeable


def test_a_kernel_names_what_is_wrong():
    with pytest.raises(ValueError, match="role: expected one of"):
        Kernel("q", attitude_maths.gyro_noise)
    with pytest.raises(TypeError, match="function: expected a numba function"):
        Kernel("Q", 3.0)
