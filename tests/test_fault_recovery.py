"""Every attitude estimator against the IMU faults of the fault matrix (quadlib.sim.imu_faults): the
error 10 s after a fault ends is back within twice its clean-data peak (+0.1°), the estimate stays
finite and the quaternion unit. For faults that last to the end of the log (dropouts, spikes) the
error stays within twice the clean peak or 1°, whichever is larger, throughout. The GPS faults are
tested in tests/quad/test_gate_recovery.py, the saturated gyro in tests/attitude/test_kesten.py and
tests/fixedwing/test_estimate.py."""

from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from quadlib import LinearKF, run_filter
from quadlib.analysis.metrics import attitude_error
from quadlib.attitude import (
    FILTERS,
    AttitudeNoise,
    altitude_model,
    baro_altitude_sensor,
    estimate_orientation,
    random_rotation,
    run_attitude_filter,
)
from quadlib.constants import G0
from quadlib.fixedwing import (
    FixedWingNoise,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.samples import Measurements
from quadlib.sim import imu_faults, imu_samples, vertical_sine

START, LENGTH, SETTLE = 8.0, 2.0, 10.0


def _check_recovery(error_deg, t, clean_peak, start, end, q):
    assert np.isfinite(error_deg).all() and np.abs(np.linalg.norm(q, axis=1) - 1.0).max() < 1e-9
    lasting = end >= t[-1]
    after = t >= (start if lasting else end + SETTLE)
    bound = max(2.0 * clean_peak, 1.0) if lasting else 2.0 * clean_peak + 0.1
    assert error_deg[after].max() <= bound, (error_deg[after].max(), clean_peak)


KESTEN_NOISE = AttitudeNoise()
TUMBLE = random_rotation(25.0, 100.0, np.random.default_rng(3))
KESTEN_LOG = imu_samples(TUMBLE, KESTEN_NOISE, np.random.default_rng(4), field_n=KESTEN_NOISE.field_n, mag_every=2)
KESTEN_FAULTS = imu_faults(KESTEN_LOG, KESTEN_NOISE.field_n, KESTEN_NOISE.accel_sigma_m_s2, np.random.default_rng(7),
                           START, LENGTH)


def _kesten_error(name, log):
    q = run_attitude_filter(FILTERS[name](KESTEN_NOISE), log).q_nb
    return np.degrees(attitude_error(q, TUMBLE.q_nb)), q


@cache
def _kesten_clean_peak(name):
    return _kesten_error(name, KESTEN_LOG)[0][TUMBLE.t > 3.0].max()


@pytest.mark.parametrize("fault", list(KESTEN_FAULTS))
@pytest.mark.parametrize("name", list(FILTERS))
def test_kestens_filters_recover_from_every_imu_fault(name, fault):
    log, end = KESTEN_FAULTS[fault]
    err, q = _kesten_error(name, log)
    _check_recovery(err, TUMBLE.t, _kesten_clean_peak(name), START, end, q)


FIELD_UT = np.array([20.0, 0.5, 45.0])  # a field in µT, 66° dip
MEKF_NOISE = replace(KESTEN_NOISE, gyro_sigma_rad_s=0.002, accel_sigma_m_s2=0.05, mag_sigma=0.3)
MEKF_LOG = imu_samples(TUMBLE, MEKF_NOISE, np.random.default_rng(5), field_n=FIELD_UT)
MEKF_FAULTS = imu_faults(MEKF_LOG, FIELD_UT, MEKF_NOISE.accel_sigma_m_s2, np.random.default_rng(8), START, LENGTH)


def _mekf_error(log):
    q = estimate_orientation(log).q
    return np.degrees(attitude_error(q, TUMBLE.q_nb)), q


@cache
def _mekf_clean_peak():
    return _mekf_error(MEKF_LOG)[0][TUMBLE.t > 5.0].max()


@pytest.mark.parametrize("fault", list(MEKF_FAULTS))
def test_the_orientation_mekf_recovers_from_every_imu_fault(fault):
    log, end = MEKF_FAULTS[fault]
    err, q = _mekf_error(log)
    _check_recovery(err, TUMBLE.t, _mekf_clean_peak(), START, end, q)


FW_NOISE = FixedWingNoise()
FLIGHT = fixedwing_flight(rate_hz=50.0)
FW_LOG = fixedwing_samples(FLIGHT, FW_NOISE, np.random.default_rng(12))
FW_FAULTS = imu_faults(FW_LOG, [1.0, 0.0, 0.0], FW_NOISE.accel_sigma_m_s2, np.random.default_rng(7), 10.0, LENGTH)


def _fw_error(factory, log):
    q = estimate_fixedwing_attitude(log, FW_NOISE, factory).x[:, :4]
    return np.degrees(attitude_error(q, FLIGHT.q_nb)), q


@cache
def _fw_clean_peak(factory):
    return _fw_error(factory, FW_LOG)[0][FLIGHT.t > 5.0].max()


@pytest.mark.parametrize("fault", list(FW_FAULTS))
@pytest.mark.parametrize("factory", [salmony_ekf, multiplicative_ekf])
def test_the_fixedwing_filters_recover_from_every_imu_fault(factory, fault):
    log, end = FW_FAULTS[fault]
    err, q = _fw_error(factory, log)
    _check_recovery(err, FLIGHT.t, _fw_clean_peak(factory), 10.0, end, q)


def test_the_altitude_filter_recovers_from_barometer_faults():
    """Outage, a stuck barometer, a persistent 20 m jump (followed: it is a new reference), 10σ
    spikes. The stuck reading must be recognised (``stuck_samples``): taken as data, it makes the
    filter put the accelerometer's motion into its gravity state g̃, and that error outlives the
    fault (7 m here 10 s later)."""
    rng = np.random.default_rng(9)
    t, s, a_z, samples = vertical_sine(40.0, rng)
    dt, tz, baro = t[1] - t[0], samples.t, samples.z
    sensor = replace(baro_altitude_sensor(0.39), reset_after_s=1.0, stuck_samples=5)

    def error(z, target=s):
        kf = LinearKF(altitude_model(0.06, 1e-5, 16 * G0), [0.0, 0.0, G0], np.diag([1.0, 0.1, 0.01]), dt)
        return np.abs(run_filter(kf, t, a_z[:, None], [Measurements(sensor, tz, z[:, None])],
                                 gate_probability=0.99).x[:, 0] - target)

    clean_peak = error(baro)[t > 5.0].max()
    window = (tz >= START) & (tz < START + 10.0)
    outage, stuck, spikes = baro.copy(), baro.copy(), baro.copy()
    outage[window] = np.nan
    stuck[window] = stuck[np.flatnonzero(window)[0]]
    hit = window & (rng.random(tz.size) < 0.05)
    spikes[hit] += rng.normal(0.0, 10 * 0.39, hit.sum())
    for z in (outage, stuck, spikes):
        assert error(z)[t >= START + 10.0 + SETTLE].max() <= 2.0 * clean_peak + 0.1
    jumped = s + np.where(t >= START, 20.0, 0.0)
    assert error(baro + np.where(tz >= START, 20.0, 0.0), jumped)[t >= START + SETTLE].max() <= 2.0 * clean_peak + 0.1
