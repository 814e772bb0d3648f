"""The one-call 3D quadrotor EKF: chapter 11's filter and tuning."""

import numpy as np
import pytest

from quadlib import ModelEKF, run_filter
from quadlib.quad.estimate import Quad3DParams, estimate_quad3d
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.quad3d import quad3d_gps_sensor, quad3d_mag_sensor, quad3d_model
from quadlib.quad.scenario import run3d_measurements, simulate_run3d


def test_the_one_call_ekf_is_chapter_8s_filter():
    run = simulate_run3d(square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(31))
    result = estimate_quad3d(run.t, run.u, run.gps, run.mag, compiled=False)  # bit for bit: the readable loop
    x0 = np.concatenate([run.gps.z[0], run.mag.z[0]])
    by_hand = run_filter(ModelEKF(quad3d_model([2.0, 2.0, 1.5 / np.sqrt(10)], 0.5 / np.sqrt(10)), x0,
                                  np.diag([1.0, 1.0, 2.0, 0.1, 0.1, 0.3, 0.1]) ** 2, run.t[1] - run.t[0]),
                         run.t, run.u, run3d_measurements(run, quad3d_gps_sensor(), quad3d_mag_sensor(0.1)),
                         engine="readable")
    np.testing.assert_array_equal(result.x, by_hand.x)
    assert np.sqrt(np.mean(np.sum((result.x[:, :3] - run.truth[:, :3]) ** 2, axis=1))) < 1.0  # metres
    assert result.sigma.shape == (run.t.size, 7)
    parts = (result.p, result.v, result.yaw)
    assert [a.shape for a in parts] == [(run.t.size, 3), (run.t.size, 3), (run.t.size,)]
    np.testing.assert_array_equal(np.column_stack(parts), result.x)
    assert Quad3DParams().P0[2, 2] == 4.0
    with pytest.raises(TypeError, match="gps: expected Samples, got tuple"):
        estimate_quad3d(run.t, run.u, (run.gps.t, run.gps.z), run.mag)
