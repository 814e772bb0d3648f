"""PX4 loaders: fields, units, frames and time alignment checked against physics and the autopilot."""

import sys

import numpy as np
import pytest

from quadlib.data import DataCorruptError, DataNotFoundError, load_px4_log, load_ulog
from quadlib.geometry import quat_to_dcm, quat_to_euler

FLIGHT = load_px4_log()
HANDHELD = load_ulog()
CURRENT = load_ulog("px4/sample_px4_events.ulg")  # PX4 v1.15: sensors in their own topics, new GPS fields


def _earth(q, v):
    return np.einsum("nij,nj->ni", quat_to_dcm(q), v)


def test_the_flight_has_its_sensors_at_their_rates():
    imu = FLIGHT.imu
    assert imu.t[0] == 0.0 and np.all(np.diff(imu.t) > 0)
    assert 69.0 < imu.t[-1] < 71.0 and 80.0 < 1 / np.median(imu.dt) < 86.0
    assert FLIGHT.gps.z.shape == (354, 6) and 4.8 < 1 / np.median(np.diff(FLIGHT.gps.t)) < 5.2
    assert FLIGHT.gps_quality.z.shape == (354, 3) and FLIGHT.gps_quality.z[:, 2].min() >= 10  # satellites
    assert np.array_equal(FLIGHT.gps.z[0, :3], [0.0, 0.0, 0.0])  # the origin is the first fix
    assert FLIGHT.baro.t.size > 3000 and 230.0 < np.median(FLIGHT.baro.z) < 245.0  # pressure altitude [m]
    np.testing.assert_allclose(np.linalg.norm(FLIGHT.attitude.z, axis=1), 1.0, atol=1e-9)


def test_the_flight_is_in_ned_and_frd():
    on_ground = FLIGHT.imu.t < 4.0
    f_n = _earth(FLIGHT.attitude.z[on_ground], FLIGHT.imu.accel[on_ground]).mean(axis=0)
    np.testing.assert_allclose(f_n, [0.0, 0.0, -9.8], atol=0.15)  # at rest the specific force points up
    mag = FLIGHT.imu.mag
    ok = ~np.isnan(mag[:, 0])
    m_n = _earth(FLIGHT.attitude.z[ok], mag[ok]).mean(axis=0)
    assert 0.45 < np.linalg.norm(m_n) < 0.65  # gauss; Indiana's field is about 0.54 G
    assert 60.0 < np.degrees(np.arctan2(m_n[2], np.hypot(m_n[0], m_n[1]))) < 70.0  # dip, downwards
    assert abs(np.degrees(np.arctan2(m_n[1], m_n[0]))) < 15.0  # north, within the declination


def test_the_imu_and_the_autopilot_share_one_clock():
    roll, pitch, yaw = quat_to_euler(FLIGHT.attitude.z)
    g = FLIGHT.imu.gyro
    gyro_yaw_rate = (np.sin(roll) * g[:, 1] + np.cos(roll) * g[:, 2]) / np.cos(pitch)
    att_yaw_rate = np.gradient(np.unwrap(yaw), FLIGHT.imu.t)
    n = g.shape[0]
    mismatch = {lag: np.sqrt(np.mean((gyro_yaw_rate[max(0, lag):n + min(0, lag)]
                                      - att_yaw_rate[max(0, -lag):n + min(0, -lag)]) ** 2)) for lag in range(-4, 5)}
    assert min(mismatch, key=mismatch.get) == 0


def test_gps_positions_agree_with_gps_velocities_and_the_autopilot():
    gps = FLIGHT.gps
    step = np.diff(gps.z[:, :3], axis=0)
    integrated = 0.5 * (gps.z[1:, 3:] + gps.z[:-1, 3:]) * np.diff(gps.t)[:, None]
    assert np.sqrt(np.mean((step - integrated)[:, :2] ** 2)) < 0.1  # m per fix, both from one receiver
    k = np.searchsorted(FLIGHT.position.t, gps.t)
    horizontal = FLIGHT.position.z[k, :2] - gps.z[:, :2]
    assert np.sqrt(np.mean(np.sum(horizontal**2, axis=1))) < 0.3  # the autopilot's origin was moved to ours
    span = gps.z[:, :2].max(axis=0) - gps.z[:, :2].min(axis=0)
    assert 15.0 < span[0] < 20.0 and 8.0 < span[1] < 12.0


def test_the_handheld_ulog():
    imu = HANDHELD.imu
    assert 1 / np.median(imu.dt) == pytest.approx(250.0, rel=1e-3)
    assert 0.5 < np.isnan(imu.mag[:, 0]).mean() < 0.7  # the magnetometer reads at about 100 Hz
    assert HANDHELD.baro is None and HANDHELD.gps is None and HANDHELD.position is None
    k = np.clip(np.searchsorted(HANDHELD.attitude.t, imu.t), 0, HANDHELD.attitude.t.size - 1)
    f_n = np.median(_earth(HANDHELD.attitude.z[k], imu.accel), axis=0)
    np.testing.assert_allclose(f_n, [0.0, 0.0, -9.7], atol=0.15)


def test_a_current_px4_ulog_loads_every_sensor():
    imu = CURRENT.imu
    assert CURRENT.imu_rate_hz == pytest.approx(250.0, rel=1e-3)
    # the magnetometer's own topic, each reading on the first IMU row after it was sampled
    assert np.isfinite(imu.mag[:, 0]).sum() == 459 and 0.2 < np.nanmedian(np.linalg.norm(imu.mag, axis=1)) < 0.7
    at_rest = imu.t < 1.0
    np.testing.assert_allclose(np.median(imu.accel[at_rest], axis=0), [0.0, 0.0, -9.8], atol=0.2)
    k = np.clip(np.searchsorted(CURRENT.attitude.t, imu.t), 0, CURRENT.attitude.t.size - 1)
    np.testing.assert_allclose(np.median(_earth(CURRENT.attitude.z[k], imu.accel), axis=0), [0.0, 0.0, -9.8], atol=0.2)
    # barometer and GPS (new field names) agree with each other and with the autopilot
    assert CURRENT.baro.t.size > 500 and abs(np.median(CURRENT.baro.z) - CURRENT.origin[2]) < 2.0
    assert CURRENT.origin[0] == pytest.approx(47.3977, abs=1e-3)
    assert CURRENT.gps_rate_hz == pytest.approx(19.2, rel=0.05)
    k = np.clip(np.searchsorted(CURRENT.position.t, CURRENT.gps.t), 0, CURRENT.position.t.size - 1)
    horizontal = np.linalg.norm(CURRENT.position.z[k, :2] - CURRENT.gps.z[:, :2], axis=1)
    assert np.median(horizontal) < 0.5 and CURRENT.position_accuracy.z.shape == (CURRENT.position.t.size, 2)
    # the parameters a filter needs
    assert CURRENT.mag_declination_rad == pytest.approx(np.radians(3.323), abs=1e-4)
    assert CURRENT.gps_delay_s == pytest.approx(0.11)
    assert HANDHELD.mag_declination_rad is None and HANDHELD.gps_delay_s is None and HANDHELD.gps_rate_hz is None


def test_the_first_fix_dates_the_log_and_places_its_declination():
    """The GPS's UTC time of the first 3D fix; the World Magnetic Model's declination there (the
    2015 flight's autopilot looked its own up, ATT_MAG_DECL_A, and logged none)."""
    assert FLIGHT.start_utc.isoformat(timespec="seconds") == "2015-06-11T01:07:59+00:00"
    assert FLIGHT.parameters["ATT_MAG_DECL_A"] == 1 and FLIGHT.mag_declination_rad is None
    assert np.degrees(FLIGHT.model_declination_rad) == pytest.approx(-4.08, abs=0.01)
    assert CURRENT.start_utc.date().isoformat() == "2024-03-18"
    assert HANDHELD.start_utc is None and HANDHELD.model_declination_rad is None  # no GPS


def test_the_raw_sensor_topics_stand_in_for_the_vehicle_ones(monkeypatch):
    from quadlib.data import px4

    vehicle_topics = ("vehicle_magnetometer", "vehicle_air_data", "vehicle_gps_position")
    raw_only = [t for t in px4._ULOG_TOPICS if t not in vehicle_topics]
    monkeypatch.setattr(px4, "_ULOG_TOPICS", raw_only)
    raw = load_ulog("px4/sample_px4_events.ulg")
    assert np.isfinite(raw.imu.mag[:, 0]).sum() > 20  # sensor_mag, logged at 1 Hz here
    k = np.searchsorted(CURRENT.baro.t, raw.baro.t).clip(0, CURRENT.baro.t.size - 1)
    assert np.median(np.abs(raw.baro.z - CURRENT.baro.z[k])) < 1.0  # sensor_baro's pressure, standard atmosphere
    assert raw.gps.t.size < CURRENT.gps.t.size  # sensor_gps is logged at 1 Hz here
    np.testing.assert_allclose(raw.origin[:2], CURRENT.origin[:2], atol=1e-5)


def test_missing_damaged_and_wrong_files_are_named(tmp_path):
    with pytest.raises(DataNotFoundError, match="px4/no_flight.px4log.*Searched"):
        load_px4_log("px4/no_flight.px4log")  # asked for in the data folder: where it was looked for
    with pytest.raises(FileNotFoundError, match="log: no such file: 'no_flight.px4log'") as info:
        load_px4_log("no_flight.px4log")  # not one of the project's logs: the caller's own missing file
    assert not isinstance(info.value, DataNotFoundError) and "01_07_59.px4log" in str(info.value)
    with pytest.raises(FileNotFoundError, match="log: no such file: .*flights/mine.ulg"):
        load_ulog(tmp_path / "flights" / "mine.ulg")
    garbage = tmp_path / "garbage.px4log"
    garbage.write_bytes(b"\xa3\x95" + bytes(range(256)) * 8)
    with pytest.raises(DataCorruptError, match="garbage.px4log"):
        load_px4_log(garbage)
    cut = tmp_path / "cut.ulg"
    cut.write_bytes(HANDHELD_BYTES()[:3000])
    with pytest.raises(DataCorruptError, match="cut.ulg.*sensor_combined"):
        load_ulog(cut)
    with pytest.raises(ValueError, match=r"log: expected a \.ulg file, got 'sample.px4log'"):
        load_ulog("sample.px4log")
    with pytest.raises(TypeError, match="log: expected a file name"):
        load_px4_log(3)


def HANDHELD_BYTES():
    from quadlib.data import data_path

    return data_path("px4/sample.ulg").read_bytes()


@pytest.mark.parametrize("loader, package", [(load_ulog, "pyulog"), (load_px4_log, "pymavlink")])
def test_a_missing_log_reader_says_what_to_install(loader, package, monkeypatch):
    monkeypatch.setitem(sys.modules, package, None)  # as if not installed
    monkeypatch.delitem(sys.modules, f"{package}.DFReader", raising=False)
    with pytest.raises(ModuleNotFoundError, match=rf"{loader.__name__}: expected the package '{package}'.*"
                                                  r'pip install "quadlib\[logs\]"'):
        loader()
