import numpy as np
import pytest

from quadlib.quad.pipeline import simple_pipeline
from quadlib.samples import Samples


def test_pipeline_holds_samples_and_differences_them():
    t = np.arange(0.0, 1.0001, 0.05)
    gps_t = np.arange(0.0, 1.0001, 0.1)
    gps = Samples(gps_t, np.column_stack([2.0 * gps_t, -gps_t, np.zeros((gps_t.size, 4))]))
    baro = Samples(gps_t, (3.0 + 0.5 * gps_t)[:, None])
    yaw_t = np.arange(0.0, 1.0001, 0.2)
    yaws = np.array([np.pi - 0.2, np.pi - 0.1, -np.pi, -np.pi + 0.1, -np.pi + 0.2, -np.pi + 0.3])
    mag = Samples(yaw_t, yaws[:, None])
    rp = np.column_stack([0.1 * t, -0.2 * t])
    x = simple_pipeline(t, rp, gps, baro, mag)
    assert x.shape == (t.size, 12)
    k = 5  # t = 0.25: latest GPS at 0.2
    np.testing.assert_allclose(x[k, :3], [0.4, -0.2, -3.1])
    np.testing.assert_allclose(x[k, 3:6], [2.0, -1.0, -0.5])  # finite differences; z is down
    np.testing.assert_allclose(x[k, 6:8], rp[k])
    np.testing.assert_allclose(x[1:, 9:11], np.tile([0.1, -0.2], (t.size - 1, 1)))
    np.testing.assert_allclose(x[10:, 11], 0.5)  # 0.1 rad per 0.2 s, across the ±π wrap
    assert np.isnan(x[0, 3])  # no difference before the second sample


def test_pipeline_skips_missing_samples_and_names_bad_input():
    t = np.arange(0.0, 1.0001, 0.1)
    z = np.column_stack([t, t, np.zeros((t.size, 4))])
    z[3:6] = np.nan  # an outage: the last valid value is held
    gps, baro, mag = Samples(t, z), Samples(t, np.ones((t.size, 1))), Samples(t, np.zeros((t.size, 1)))
    x = simple_pipeline(t, np.zeros((t.size, 2)), gps, baro, mag)
    np.testing.assert_allclose(x[3:6, 0], 0.2)
    np.testing.assert_allclose(x[6, 3], 1.0)  # (0.6 - 0.2) / 0.4
    with pytest.raises(ValueError, match="gps: expected at least two valid samples, got 1"):
        simple_pipeline(t, np.zeros((t.size, 2)), Samples(t[:1], z[:1]), baro, mag)
    with pytest.raises(ValueError, match=r"roll_pitch: expected shape \(11, 2\), got \(11, 3\)"):
        simple_pipeline(t, np.zeros((t.size, 3)), gps, baro, mag)
