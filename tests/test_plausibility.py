"""The one-call estimators refuse logs whose units are wrong, naming the caller's argument."""

import warnings

import numpy as np
import pytest

from quadlib.attitude import estimate_orientation
from quadlib.constants import G0
from quadlib.data import load_broad_trial, load_px4_log
from quadlib.nav import InsParams, estimate_ins
from quadlib.plausibility import check_gps_metres, check_imu_units, degrees_likelier, warn_unused
from quadlib.samples import Samples

TRIAL = load_broad_trial("02_undisturbed_slow_rotation_B")
N = 20_000
T, GYR, ACC, MAG = (a[:N] for a in (TRIAL.log.t, TRIAL.log.gyro, TRIAL.log.accel, TRIAL.log.mag))


@pytest.mark.parametrize(("change", "argument", "says"), [
    (dict(acc=ACC / G0), "acc", "it looks like g"),
    (dict(acc=ACC * 100.0), "acc", "median norm near 9.81"),
    (dict(t=T * 1e3), "t", "it looks like ms"),
    (dict(t=T * 1e6), "t", "it looks like µs"),
    (dict(gyr=np.degrees(GYR)), "gyr", "°/s"),
])
def test_a_unit_mistake_in_the_raw_arrays_is_named(change, argument, says):
    arrays = dict(t=T, gyr=GYR, acc=ACC, mag=MAG) | change
    with pytest.raises(ValueError) as err:
        estimate_orientation(**arrays)
    message = str(err.value)
    assert message.startswith(f"{argument}: expected") and says in message and "got" in message


def test_the_right_units_pass_on_every_shipped_log():
    from quadlib.data import broad_trial_names, data_path, load_ulog

    logs = [load_broad_trial(name).log for name in broad_trial_names()]
    logs += [load_px4_log().imu, load_ulog(data_path("px4/sample.ulg")).imu,
             load_ulog(data_path("px4/sample_px4_events.ulg")).imu]
    for log in logs:
        check_imu_units(log.t, log.gyro, log.accel)
        ratio = degrees_likelier(log.t, log.gyro, log.accel)
        assert ratio is None or ratio < 1.5


def test_a_gyro_in_degrees_is_told_apart_on_every_trial_that_turns_enough():
    from quadlib.data import broad_trial_names

    told = 0
    for name in broad_trial_names():
        log = load_broad_trial(name).log
        ratio = degrees_likelier(log.t, np.degrees(log.gyro), log.accel)
        if ratio is not None:
            assert ratio > 2.0, name
            told += 1
    assert told >= 8


def test_an_imu_log_is_named_by_its_fields():
    log = TRIAL.log.slice(0, N)
    from dataclasses import replace

    with pytest.raises(ValueError, match=r"^t.accel: expected specific force in m/s²"):
        estimate_orientation(replace(log, accel=log.accel / G0))


FLIGHT = load_px4_log()


def test_gps_in_degrees_is_refused_by_the_ins():
    gps = FLIGHT.gps
    lat_lon_alt = gps.z.copy()
    lat_lon_alt[:, 0] = FLIGHT.origin[0] + gps.z[:, 0] / 111_000.0
    lat_lon_alt[:, 1] = FLIGHT.origin[1] + gps.z[:, 1] / 76_000.0
    lat_lon_alt[:, 2] = FLIGHT.origin[2] - gps.z[:, 2]
    with pytest.raises(ValueError, match=r"^gps: expected NED positions \[m\].*degrees"):
        estimate_ins(FLIGHT.imu, Samples(gps.t, lat_lon_alt), FLIGHT.baro, InsParams())
    check_gps_metres(gps.t, gps.z)  # the loader's metres pass


def test_the_ins_names_its_log_fields():
    from dataclasses import replace

    imu = replace(FLIGHT.imu, accel=FLIGHT.imu.accel / G0)
    with pytest.raises(ValueError, match=r"^log.accel: expected specific force in m/s².*looks like g"):
        estimate_ins(imu, FLIGHT.gps, FLIGHT.baro, InsParams())


def test_a_sensor_left_unused_is_reported():
    from quadlib.replay import SensorTrace

    k = 200
    flags = np.zeros(k, bool)
    trace = SensorTrace(t=np.arange(k, dtype=float), innovation=np.full((k, 1), np.nan), S=np.full((k, 1, 1), np.nan),
                        nis=np.full(k, np.nan), used=flags.copy(), rejected=np.ones(k, bool), reset=flags.copy(),
                        missing=flags.copy(), duplicate=flags.copy())
    with pytest.warns(UserWarning, match=r"gravity: used 0 of the 200 samples offered \(200 rejected by the χ² gate\)"):
        warn_unused({"gravity": trace})
    used = SensorTrace(**{**trace.__dict__, "used": np.ones(k, bool)})
    at_rest_only = SensorTrace(**{**trace.__dict__, "missing": np.ones(k, bool)})  # a zero-rate update in motion
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_unused({"gravity": used, "zero rate": at_rest_only})


def test_a_magnetometer_in_another_frame_is_reported():
    swapped = MAG[:, [1, 0, 2]] * np.array([1.0, 1.0, -1.0])  # an MPU-9250's magnetometer against its gyro
    with pytest.warns(UserWarning, match=r"^mag: expected a field in gyr's frame"):
        estimate_orientation(T, GYR, ACC, swapped)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        estimate_orientation(T, GYR, ACC, MAG)


def test_every_shipped_magnetometer_follows_its_gyro():
    from quadlib.data import broad_trial_names
    from quadlib.plausibility import field_follows_gyro

    for name in broad_trial_names():
        log = load_broad_trial(name).log
        assert field_follows_gyro(log.t, log.gyro, log.mag) < 1.0, name
        swapped = log.mag[:, [1, 0, 2]] * np.array([1.0, 1.0, -1.0])
        assert field_follows_gyro(log.t, log.gyro, swapped) > 1.0, name


def test_streams_without_a_reading_are_named_and_a_late_first_gyro_reading_is_held_back():
    with pytest.raises(ValueError, match=r"^gyr: expected at least one finite rate"):
        estimate_orientation(T[:3000], np.full((3000, 3), np.nan), ACC[:3000], MAG[:3000])
    with pytest.raises(ValueError, match=r"^acc: expected at least one finite specific force"):
        estimate_orientation(T[:3000], GYR[:3000], np.full((3000, 3), np.nan), MAG[:3000])
    late = GYR[:3000].copy()
    late[:5] = np.nan
    assert np.isfinite(estimate_orientation(T[:3000], late, ACC[:3000], MAG[:3000]).q).all()


def test_a_magnetometer_the_filter_cannot_use_is_named_with_why():
    with pytest.warns(UserWarning, match=r"^mag: expected at least one reading that gives a heading, got none"):
        estimate_orientation(T, GYR, ACC, np.full_like(MAG, np.nan))
    far_off = MAG.copy()
    # a magnet moving about: 1.5 to 4.5 times the start's field, every later reading fails the strength check
    far_off[50:] *= 3.0 + 1.5 * np.sin(2 * np.pi * T[50:] / 5.0)[:, None]
    with pytest.warns(UserWarning, match=r"^mag: the heading update used \d+ of its 20000 readings \(\d+ failed the "
                                         r"plausibility checks, \d+ were refused by the χ² gate\)"):
        estimate_orientation(T, GYR, ACC, far_off)
