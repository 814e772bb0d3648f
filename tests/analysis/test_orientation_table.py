"""The BROAD comparison's adapters: every estimator, quadlib's and the other libraries', returns
sensor → NED on a simulated log whose truth is known, so a wrong frame conversion shows."""

import numpy as np
import pytest

from quadlib.analysis.metrics import broad_errors
from quadlib.analysis.orientation_table import estimator_names, field_at_rest, orientation_estimate
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.imu import ImuLog, ImuNoise
from quadlib.sim.imu import BodyMotion, imu_samples

FIELD_UT = earth_field_ned(48.0, np.radians(67.0))
NOISE = ImuNoise(gyro_sigma_rad_s=0.003, accel_sigma_m_s2=0.03, mag_sigma=0.2)


def _log(motion, seed=1):
    return imu_samples(motion, NOISE, np.random.default_rng(seed), field_n=FIELD_UT)


def test_the_field_is_read_from_the_first_second_at_rest():
    t = np.arange(200) / 100.0
    q = np.tile([np.cos(0.4), np.sin(0.4), 0.0, 0.0], (t.size, 1))  # rolled 46°
    from quadlib.geometry.quaternion import quat_to_dcm
    f_b = np.einsum("nji,j->ni", quat_to_dcm(q), [0.0, 0.0, -9.80665])
    still = BodyMotion(t, q, np.zeros((t.size, 3)), f_b)
    strength, dip = field_at_rest(_log(still))
    assert strength == pytest.approx(48.0, abs=0.1) and np.degrees(dip) == pytest.approx(67.0, abs=0.3)


@pytest.mark.parametrize("name", [n for n in estimator_names() if n != "fixed-wing ES-UKF"])
def test_every_estimator_returns_sensor_to_ned(name):
    """A slow tumble from rest: after 8 s every estimator is within a few degrees of the truth (a
    frame mistake is a 90° or 180° error)."""
    motion = random_rotation(12.0, 100.0, np.random.default_rng(4), rms_rate_rad_s=0.4)
    still = BodyMotion(np.arange(100) / 100.0, np.tile(motion.q_nb[0], (100, 1)), np.zeros((100, 3)),
                       np.tile(motion.f_b[0], (100, 1)))  # a second at rest first, for the field
    t = np.r_[still.t, 1.0 + motion.t[1:]]
    both = BodyMotion(t, np.r_[still.q_nb, motion.q_nb[1:]], np.r_[still.omega_b, motion.omega_b[1:]],
                      np.r_[still.f_b, motion.f_b[1:]])
    log = _log(both)
    late = t > 8.0
    errors = broad_errors(orientation_estimate(name, log), both.q_nb, late)
    assert errors["total_deg"] < 6.0, errors


def test_unknown_names_and_logs_without_a_magnetometer_are_refused():
    log = ImuLog(np.arange(3.0), np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="name: expected one of"):
        orientation_estimate("EKF", log)
    with pytest.raises(ValueError, match="log.mag: expected magnetometer samples, got None"):
        orientation_estimate("VQF", log)


def test_error_components_split_a_known_error_like_broad_errors():
    from quadlib.analysis.orientation_table import error_components
    from quadlib.geometry.quaternion import quat_from_rotvec, quat_multiply

    truth = np.tile([np.cos(0.2), 0.0, np.sin(0.2), 0.0], (3, 1))
    turn = quat_multiply(quat_from_rotvec(np.radians([0.0, 0.0, -3.0])), quat_from_rotvec(np.radians([1.0, 0.0, 0.0])))
    estimate = quat_multiply(turn, truth)  # an earth-frame error: 1° of roll, then 3° to the west
    truth[1] = np.nan
    heading, inclination = error_components(estimate, truth)
    np.testing.assert_allclose(heading[[0, 2]], -3.0, atol=1e-9)
    np.testing.assert_allclose(inclination[[0, 2]], 1.0, atol=1e-9)
    assert np.isnan(heading[1]) and np.isnan(inclination[1])
    rms = broad_errors(estimate[[0, 2]], truth[[0, 2]])
    assert rms["heading_deg"] == pytest.approx(3.0) and rms["inclination_deg"] == pytest.approx(1.0)
