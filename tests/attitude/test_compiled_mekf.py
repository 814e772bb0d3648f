"""The compiled orientation loop gives what the readable one (ModelEKF driven by run_filter, and
rts_smooth offline) gives: the same states, covariances and sensor traces, to 1e-10, through every
branch — rest, dropouts, held gyro rows, gate rejections, a saturated gyro, no magnetometer."""

import numpy as np
import pytest

from quadlib.attitude.compiled_mekf import calm_samples, inertial_lowpass_pass
from quadlib.attitude.orientation import OrientationParams, inertial_lowpass, orientation_run, rest_mask
from quadlib.attitude.tumble import random_rotation
from quadlib.constants import earth_field_ned
from quadlib.data import load_broad_trial
from quadlib.geometry.quaternion import quat_from_rotvec, quat_to_dcm
from quadlib.imu import ImuLog, ImuNoise
from quadlib.sim.imu import imu_samples


def _simulated_log():
    """20 s of tumbling at 100 Hz with a gyro bias, dropouts in every stream, a field turned by 40°
    for 2 s and a 1.5 m/s² push for 1 s (plausible in norm and dip, so only the gate can refuse them)
    and a gyro that clips."""
    motion = random_rotation(20.0, 100.0, np.random.default_rng(5), rms_rate_rad_s=1.0)
    noise = ImuNoise(gyro_sigma_rad_s=0.002, gyro_bias_rad_s=(0.004, -0.003, 0.002), accel_sigma_m_s2=0.05,
                     mag_sigma=0.3)
    log = imu_samples(motion, noise, np.random.default_rng(6), field_n=earth_field_ned(50.0, np.radians(65.0)))
    rng = np.random.default_rng(7)
    gyro, accel, mag = log.gyro.copy(), log.accel.copy(), log.mag.copy()
    for stream in (gyro, accel, mag):
        stream[rng.random(len(log)) < 0.05] = np.nan
    gyro[0] = log.gyro[0]  # a held gyro row needs a first one to hold
    turned = (log.t > 8.0) & (log.t < 10.0)
    mag[turned] = mag[turned] @ quat_to_dcm(quat_from_rotvec([0.0, 0.0, np.radians(40.0)])).T
    accel[(log.t > 12.0) & (log.t < 13.0)] += [1.5, 0.0, 0.0]
    gyro_range = 0.8 * float(np.nanmax(np.abs(gyro)))
    return ImuLog(log.t, np.clip(gyro, -gyro_range, gyro_range), accel, mag), gyro_range


SIMULATED, GYRO_RANGE = _simulated_log()
BROAD = load_broad_trial("24_disturbed_tapping_A").log.slice(0, 2500)  # rest, then the first taps


CASES = {
    "BROAD slice": (BROAD, OrientationParams()),
    "simulated, tight gate": (SIMULATED, OrientationParams(gate_probability=0.9, gyro_range_rad_s=GYRO_RANGE,
                                                           gravity_sigma_m_s2=0.2, accel_tau_s=None)),
    "no magnetometer, no rest, no gate": (ImuLog(SIMULATED.t, SIMULATED.gyro, SIMULATED.accel),
                                          OrientationParams(gate_probability=None, rest_min_s=None)),
}


@pytest.mark.parametrize("offline", [False, True], ids=["forward", "smoother"])
@pytest.mark.parametrize("case", list(CASES))
def test_the_compiled_loop_equals_the_readable_one(case, offline, assert_same_run):
    log, params = CASES[case]
    compiled = orientation_run(log, params, offline=offline)
    readable = orientation_run(log, params, offline=offline, compiled=False)
    assert_same_run(compiled, readable)


def test_the_cases_reach_every_branch():
    """The comparisons above are only worth something if each branch happened in them."""
    broad = orientation_run(*CASES["BROAD slice"])
    assert broad.sensors["zero rate"].used.sum() > 100  # rest at the start
    simulated = orientation_run(*CASES["simulated, tight gate"])
    for name in ("gravity", "heading"):
        trace = simulated.sensors[name]
        assert trace.rejected.sum() > 5 and trace.missing.sum() > 50, name
    assert simulated.held_input.sum() > 50
    low_passed = orientation_run(SIMULATED, OrientationParams(gate_probability=0.9, gravity_sigma_m_s2=0.2))
    assert not low_passed.sensors["gravity"].rejected.any()  # the averaged gravity is never gated
    assert (np.abs(SIMULATED.gyro) >= 0.999 * GYRO_RANGE).any(axis=1).sum() > 20  # saturated steps


def test_the_compiled_lowpasses_equal_their_interpreted_source():
    params = OrientationParams()
    gyro, accel = np.ascontiguousarray(SIMULATED.gyro), SIMULATED.accel
    usable = ~np.isnan(accel).any(axis=1)
    for backward in (False, True):
        np.testing.assert_array_equal(
            inertial_lowpass_pass(SIMULATED.t, gyro, accel, usable, 3.0, backward),
            inertial_lowpass_pass.py_func(SIMULATED.t, gyro, accel, usable, 3.0, backward))
    args = (SIMULATED.t, SIMULATED.gyro, accel, params.rest_gyro_rad_s, params.rest_accel_m_s2, 0.5)
    assert np.array_equal(calm_samples(*args), calm_samples.py_func(*args))
    assert rest_mask(SIMULATED, 0.1, 0.5, 0.5).dtype == bool
    assert inertial_lowpass(SIMULATED, 3.0).shape == accel.shape


def test_repeated_timestamps_run_the_readable_loop(assert_same_run):
    """run_filter drops a sample whose time repeats the one before within its precision; the
    compiled loop does not, so such a log goes to the readable one (same result either way)."""
    t = SIMULATED.t.copy()
    t[100] = t[99] + 1e-15  # later than t[99], but not by more than the times' precision
    log = ImuLog(t, SIMULATED.gyro, SIMULATED.accel, SIMULATED.mag)
    compiled, readable = orientation_run(log), orientation_run(log, compiled=False)
    assert readable.sensors["gravity"].duplicate[100]
    assert_same_run(compiled, readable)
