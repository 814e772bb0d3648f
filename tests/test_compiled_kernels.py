"""The compiled loops' shared helpers: a loop Python calls compiles one machine code whatever the
layout of the arrays it is given."""

import numpy as np

from quadlib.kernels.lowpass import calm_samples


def test_a_view_or_a_read_only_log_reuses_the_loops_one_compiled_version():
    rng = np.random.default_rng(0)
    t = np.arange(200) * 0.01
    gyro, accel = rng.normal(size=(200, 3)) * 0.01, rng.normal(size=(200, 3)) * 0.1 + [0.0, 0.0, -9.8]
    expected = calm_samples(t, gyro, accel, 0.05, 0.5, 0.5)
    versions = len(calm_samples.__wrapped__.signatures)
    frozen = accel.copy()
    frozen.setflags(write=False)
    wide = np.hstack([gyro, accel])  # its columns are views with a row stride of six
    for g, a in ((wide[:, :3], wide[:, 3:]), (gyro, frozen), (np.asfortranarray(gyro), accel)):
        np.testing.assert_array_equal(calm_samples(t, g, a, 0.05, 0.5, 0.5), expected)
    assert len(calm_samples.__wrapped__.signatures) == versions
    assert not frozen.flags.writeable  # the caller's array is left as it was
