"""Faults in the 3D EKF (chapter 11): a GPS outage, a magnetometer disturbance, yaw across ±π."""

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, ModelUKF, Sensor, run_filter
from quadlib.geometry.rotations import wrap_angle
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.quad3d import quad3d_gps_sensor, quad3d_mag_sensor, quad3d_model, quad3d_ukf_options
from quadlib.quad.scenario import simulate_run3d

FLIGHT = square_course(leg_s=4.0, turn_s=2.0)  # yaw crosses ±π in the third turn (16-18 s)
MODEL = quad3d_model([2.0, 2.0, 0.47], 0.16)
GPS, MAG = quad3d_gps_sensor(), quad3d_mag_sensor(0.1)
P0 = np.diag([1.0, 1.0, 2.0, 0.1, 0.1, 0.3, 0.1]) ** 2


@pytest.fixture(scope="module")
def run():
    return simulate_run3d(FLIGHT, SensorNoise3D(), np.random.default_rng(11))


def _filter(run, gps_z=None, mag_z=None, mag_sensor=MAG, gate=None, ukf=False):
    meas = [Measurements(GPS, run.gps.t, run.gps.z if gps_z is None else gps_z),
            Measurements(mag_sensor, run.mag.t, run.mag.z if mag_z is None else mag_z)]
    f = (ModelUKF(MODEL, run.truth[0], P0, 0.02, **quad3d_ukf_options()) if ukf
         else ModelEKF(MODEL, run.truth[0], P0, 0.02))
    res = run_filter(f, run.t, run.u, meas, gate_probability=gate)
    err = res.x - run.truth
    err[:, 6] = wrap_angle(err[:, 6])
    return res, err


def test_gps_outage_sigma_grows_and_the_filter_recovers(run):
    gps_z = run.gps.z.copy()
    outage = (run.gps.t >= 8.0) & (run.gps.t < 18.0)
    gps_z[outage] = np.nan
    res, err = _filter(run, gps_z=gps_z)
    sigma_h = np.hypot(res.sigma[:, 0], res.sigma[:, 1])
    err_h = np.hypot(err[:, 0], err[:, 1])
    before, end, after = (int(np.argmin(np.abs(run.t - s))) for s in (7.98, 17.98, 20.0))
    assert res.sensors["gps"].missing.sum() == outage.sum()
    assert sigma_h[end] > 5 * sigma_h[before]  # the filter knows it is dead reckoning
    assert err_h[end] > 1.0  # and it does drift
    assert err_h[after] < 1.0 and sigma_h[after] < 2 * sigma_h[before]  # two seconds of GPS: recovered


def test_magnetometer_disturbance_is_rejected_by_the_gate(run):
    disturbed = (run.mag.t >= 5.0) & (run.mag.t < 8.0)
    mag_z = run.mag.z.copy()
    mag_z[disturbed] = wrap_angle(mag_z[disturbed] + np.radians(40.0))
    _, err_open = _filter(run, mag_z=mag_z)
    gated, err_gated = _filter(run, mag_z=mag_z, gate=0.999)
    rejected = gated.sensors["mag"].rejected
    assert np.degrees(np.abs(err_open[:, 6]).max()) > 20.0  # without a gate the heading follows the disturbance
    assert rejected[disturbed].mean() > 0.95 and rejected[~disturbed].mean() < 0.01
    assert np.degrees(np.abs(err_gated[run.t > 1.0, 6]).max()) < 5.0


@pytest.mark.parametrize("ukf", [False, True], ids=["EKF", "UKF"])
def test_yaw_crossing_pi_has_no_glitch(run, ukf):
    assert np.any(np.abs(np.diff(run.truth[:, 6])) > np.pi)  # the truth does wrap
    _, err = _filter(run, ukf=ukf)
    settled = run.t > 1.0  # after the first second (the start is one noisy heading sample)
    assert np.degrees(np.abs(err[settled, 6]).max()) < 5.0


def test_an_unwrapped_yaw_innovation_does_glitch(run):
    plain = Sensor(name="mag", measurement_names=("yaw [rad]",), h=MAG.h, H=MAG.H, R=MAG.R)
    _, err = _filter(run, mag_sensor=plain)
    assert np.degrees(np.abs(err[:, 6]).max()) > 90.0

