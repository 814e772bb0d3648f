"""The inertial navigation EKF: its model against finite differences, physics at rest, and the
estimator on chapter 8's simulated square (accuracy against the 7-state EKF, consistency)."""

import numpy as np
import pytest

from quadlib.constants import G0
from quadlib.geometry import quat_from_euler, quat_to_dcm
from quadlib.imu import ImuLog
from quadlib.nav import InsParams, estimate_ins, imu_blocks, ins_gps_sensor, ins_model
from quadlib.samples import Samples

MODEL = ins_model(0.01, 0.2, 1e-4, 1e-3)


def _state(rng):
    q = quat_from_euler(0.3, -0.2, 2.0)
    return np.concatenate([q, rng.normal(size=3), rng.normal(size=3) * 5, rng.normal(size=3) * 0.01,
                           rng.normal(size=3) * 0.1])


@pytest.mark.parametrize("dt", [0.004, 0.05])
def test_the_error_jacobian_matches_finite_differences(dt):
    rng = np.random.default_rng(3)
    x, u = _state(rng), np.r_[0.4, -0.7, 1.1, 1.0, -0.5, -9.0]
    g0 = MODEL.g(x, u, dt)
    eps = 1e-6
    fd = np.column_stack([(MODEL.residual_x(MODEL.g(MODEL.state_add(x, eps * e), u, dt), g0)
                           - MODEL.residual_x(MODEL.g(MODEL.state_add(x, -eps * e), u, dt), g0)) / (2 * eps)
                          for e in np.eye(15)])
    np.testing.assert_allclose(MODEL.G(x, u, dt), fd, atol=1e-7)


def test_a_level_imu_at_rest_stays_put():
    x = np.r_[1.0, 0, 0, 0, np.zeros(12)]
    for _ in range(100):
        x = MODEL.g(x, np.r_[0.0, 0.0, 0.0, 0.0, 0.0, -G0], 0.01)
    np.testing.assert_allclose(x[4:10], 0.0, atol=1e-12)


def test_a_tilted_imu_at_rest_stays_put_and_a_tilt_error_drifts_at_g_times_the_angle():
    q = quat_from_euler(0.2, -0.1, 1.0)
    f = quat_to_dcm(q).T @ np.array([0.0, 0.0, -G0])  # what the accelerometer reads at rest
    x = np.r_[q, np.zeros(12)]
    y = MODEL.g(x, np.r_[0.0, 0.0, 0.0, f], 1.0)
    np.testing.assert_allclose(y[4:10], 0.0, atol=1e-12)
    tilted = MODEL.state_add(x, np.r_[0.01, 0, 0, np.zeros(12)])  # 10 mrad about body x
    drift = MODEL.g(tilted, np.r_[0.0, 0.0, 0.0, f], 1.0)[4:7]
    # body x is pitched 0.1 rad out of the horizontal: only its horizontal part tilts gravity
    assert np.linalg.norm(drift) == pytest.approx(G0 * 0.01 * np.cos(0.1), rel=1e-4)


def test_the_gps_sensor_without_height_measures_five_components():
    sensor = ins_gps_sensor((1.0, 1.0, 3.0), (0.1, 0.1, 0.2), use_height=False)
    x = np.r_[1.0, 0, 0, 0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, np.zeros(6)]
    np.testing.assert_array_equal(sensor.h(x), [4.0, 5.0, 1.0, 2.0, 3.0])
    assert sensor.groups == ((0, 1), (2, 3, 4))
    np.testing.assert_allclose(np.sqrt(np.diag(sensor.R)), [1.0, 1.0, 0.1, 0.1, 0.2])


def test_imu_blocks_average_and_keep_the_block_start_times():
    t = np.arange(10) * 0.1
    gyro = np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)])
    log = ImuLog(t, gyro, np.tile([0.0, 0.0, -G0], (10, 1)))
    tb, u = imu_blocks(log, 3)
    np.testing.assert_allclose(tb, [0.0, 0.3, 0.6])
    np.testing.assert_allclose(u[:, 0], [1.0, 4.0, 7.0])
    with pytest.raises(ValueError, match=r"decimate: expected an int in \[1, 5\]"):
        imu_blocks(log, 6)


def test_bad_inputs_are_named():
    log = ImuLog(np.arange(50) * 0.01, np.zeros((50, 3)), np.tile([0.0, 0.0, -G0], (50, 1)))
    with pytest.raises(ValueError, match=r"gps: expected samples of \[pn, pe, pd, vn, ve, vd\]"):
        estimate_ins(log, Samples(np.r_[0.0], np.zeros((1, 3))))
    with pytest.raises(ValueError, match="gps: expected at least one fix within"):
        estimate_ins(log, Samples(np.r_[5.0], np.zeros((1, 6))))
    with pytest.raises(TypeError, match="params: expected"):
        estimate_ins(log, Samples(np.r_[0.0], np.zeros((1, 6))), params={"gyro_sigma_rad_s": 0.1})
    with pytest.raises(ValueError, match="InsParams.gps_delay_s"):
        InsParams(gps_delay_s=-0.1)
