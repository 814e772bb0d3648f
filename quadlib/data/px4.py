"""PX4 logs in the project's conventions: the legacy sdlog2 ``.px4log`` and the ULog ``.ulg``.

Both give a :class:`FlightLog`: the IMU as an :class:`~quadlib.imu.ImuLog` (body frame FRD, gyro
[rad/s], specific force [m/s²], magnetometer [gauss]), the barometer, the GPS and the autopilot's
own estimates, on one time axis in seconds from the log's first IMU sample. PX4 already logs in
NED/FRD with scalar-first quaternions, so only units and times change, and GPS fixes are turned
into NED metres about the first 3D fix (:func:`quadlib.geometry.geodetic.geodetic_to_ned`).

* ``.px4log`` (read with pymavlink's ``DFReader``): every logging cycle starts with a ``TIME``
  message (``StartTime``, µs since boot); the messages after it carry no time of their own and get
  that one. A sensor logged again without a new reading repeats its values; a magnetometer or
  barometer repeat is marked missing (NaN), because the filters must not fuse one reading twice.
  ``GPS`` is logged once per fix (its ``GPSTime`` has whole seconds only); rows with a 3D fix are kept.
* ``.ulg`` (read with pyulog), from PX4 v1.6 to current: ``sensor_combined`` holds gyro and
  accelerometer at the IMU's rate. Logs before about v1.11 also carry the latest magnetometer and
  barometer readings there, with their own relative timestamps: a reading whose timestamp did not
  change is marked missing, and a stream whose relative timestamp is the "invalid" marker 2³¹ − 1
  throughout (no such sensor) is left out. Later logs put them in their own topics, read in this
  order of preference: the magnetometer from ``vehicle_magnetometer`` or ``sensor_mag``, the
  barometer from ``vehicle_air_data`` (its altitude) or ``sensor_baro`` (its pressure, through the
  standard atmosphere at the log's ``SENS_BARO_QNH``), GPS from ``vehicle_gps_position`` or
  ``sensor_gps`` in either generation of field names (``lat`` [1e-7 deg], ``alt`` [mm] before
  v1.14; ``latitude_deg``, ``altitude_msl_m`` after). Each reading is timed by its
  ``timestamp_sample`` where the log has one (the moment the sensor sampled, not when the message
  was published) and placed on the first IMU row at or after that time; of a multi-instance topic
  the first instance is read (for ``vehicle_*`` topics, the one the autopilot selected).
* Gyro timing: ``sensor_combined.gyro_rad`` is the rate integrated over the ``gyro_integral_dt``
  before its timestamp; the loader keeps each row where it is logged (``ImuLog.gyro[k]`` applied
  over the step after ``t[k]``), which is the timing that agrees best with PX4's own attitude on
  these logs.

The log's parameters are kept (``FlightLog.parameters``); :attr:`FlightLog.mag_declination_rad`
and :attr:`FlightLog.gps_delay_s` read the two a filter needs (``EKF2_MAG_DECL``, ``EKF2_GPS_DELAY``).

The autopilot's attitude is ``ATT`` (roll, pitch, yaw; the quaternion fields of this log version
are zero) or ``vehicle_attitude`` (a quaternion); its position ``LPOS`` is NED about its own
reference point, which is moved to this log's origin so the two can be compared.
"""

from __future__ import annotations

import datetime
import importlib
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from quadlib.constants import G0
from quadlib.data.paths import KNOWN_FILES, SOURCES, DataCorruptError, data_path
from quadlib.geometry.geodetic import geodetic_to_ned, model_declination_rad
from quadlib.geometry.quaternion import quat_from_euler
from quadlib.imu import ImuLog
from quadlib.samples import Samples

__all__ = ["FlightLog", "load_px4_log", "load_ulog"]

_ULOG_INVALID = 2**31 - 1  # sensor_combined's relative timestamp of a stream with no reading


@dataclass(frozen=True)
class FlightLog:
    """One PX4 log in the project's conventions; times [s] from the first IMU sample.

    Attributes
    ----------
    name : str
        The file's name.
    imu : ImuLog
        Gyro [rad/s], accelerometer [m/s²], magnetometer [gauss] (NaN rows: no new reading), FRD.
    baro : Samples or None
        Barometric (pressure) altitude [m] as the autopilot computed it, shape (K,).
    gps : Samples or None
        3D fixes: NED position about ``origin`` [m] and NED velocity [m/s], shape (K, 6).
    gps_quality : Samples or None
        Per fix: horizontal and vertical accuracy estimates EPH, EPV [m] and the number of
        satellites, shape (K, 3).
    origin : (3,) ndarray or None
        Latitude [deg], longitude [deg] and GPS altitude [m] of the first 3D fix.
    attitude : Samples
        The autopilot's attitude ``q_nb`` (scalar first), shape (K, 4).
    position : Samples or None
        The autopilot's NED position about ``origin`` [m] and velocity [m/s], shape (K, 6); its
        down axis keeps the autopilot's own height reference.
    position_accuracy : Samples or None
        The autopilot's own horizontal and vertical position accuracy (EPH, EPV) [m], shape (K, 2),
        where the log has them.
    parameters : dict
        The autopilot's parameters at the start of the log, by name (empty where the log has none).
    start_utc : datetime.datetime or None
        The UTC time of the first 3D fix, where the GPS gives one.
    """

    name: str
    imu: ImuLog
    baro: Samples | None
    gps: Samples | None
    gps_quality: Samples | None
    origin: np.ndarray | None
    attitude: Samples
    position: Samples | None
    position_accuracy: Samples | None = None
    parameters: dict = field(default_factory=dict)
    start_utc: datetime.datetime | None = None

    @property
    def mag_declination_rad(self) -> float | None:
        """The magnetic declination the autopilot used, ``EKF2_MAG_DECL`` [deg] in radians, or None.

        With bit 0 of ``EKF2_DECL_TYPE`` set, PX4 looks the declination up in its field model from
        the GPS position, and (bit 1) saves the value it found into ``EKF2_MAG_DECL`` when it
        disarms: the logged value is then the last flight's lookup, right wherever the vehicle flies
        from the same site."""
        value = self.parameters.get("EKF2_MAG_DECL")
        return None if value is None else float(np.radians(value))

    @property
    def model_declination_rad(self) -> float | None:
        """The World Magnetic Model's declination [rad] at the first fix (``origin``) on its date
        (``start_utc``), or None without them (:func:`~quadlib.geometry.model_declination_rad`)."""
        if self.origin is None or self.start_utc is None:
            return None
        return model_declination_rad(self.origin, self.start_utc)

    @property
    def gps_delay_s(self) -> float | None:
        """The GPS measurement delay the autopilot assumed, ``EKF2_GPS_DELAY`` [ms] in seconds, or None."""
        value = self.parameters.get("EKF2_GPS_DELAY")
        return None if value is None else float(value) * 1e-3

    @property
    def imu_rate_hz(self) -> float:
        """The IMU's rate [Hz], from the median interval between its rows."""
        return float(1.0 / np.median(self.imu.dt))

    @property
    def gps_rate_hz(self) -> float | None:
        """The rate of the GPS fixes [Hz], from their median interval; None without GPS."""
        if self.gps is None or self.gps.t.size < 2:
            return None
        return float(1.0 / np.median(np.diff(self.gps.t)))


def _resolve(log: str | os.PathLike, suffix: str) -> Path:
    """The file to read: an existing path as given; a name of the project's data (``"sample.ulg"``,
    ``"px4/sample.ulg"``) through :func:`~quadlib.data.data_path`, which says where to fetch it; any
    other path that does not exist is the caller's own missing file."""
    if not isinstance(log, (str, os.PathLike)):
        raise TypeError(f"log: expected a file name such as 'px4/sample.ulg' or a path, got {type(log).__name__}")
    path = Path(log)
    if path.suffix != suffix:
        raise ValueError(f"log: expected a {suffix} file, got {str(log)!r}")
    if path.is_file():
        return path
    in_data_folder = not path.is_absolute() and path.parent.as_posix() in (".", "px4")
    if in_data_folder and (f"px4/{path.name}" in KNOWN_FILES or path.parent.as_posix() == "px4"):
        return data_path(f"px4/{path.name}")
    shipped = ", ".join(sorted(k for k in KNOWN_FILES if k.startswith("px4/") and k.endswith(suffix)))
    raise FileNotFoundError(f"log: no such file: {str(path)!r} (the project's own {suffix} logs are {shipped})")


def _corrupt(path: Path, what: str, err=None) -> DataCorruptError:
    source = SOURCES.get(f"px4/{path.name}", "the public source it came from")
    detail = f" ({err})" if err is not None else ""
    return DataCorruptError(f"data file {str(path)!r} {what}{detail}; fetch it again from {source}")


def _repeats_missing(t, values) -> np.ndarray:
    """``values`` with a row equal to the one before it set to NaN (no new reading)."""
    v = np.array(values, dtype=float)
    same = np.r_[False, np.all(v[1:] == v[:-1], axis=1)]
    v[same] = np.nan
    return v


def _position_in_origin(lpos_ned, ref_lla, origin) -> np.ndarray:
    """The autopilot's local NED (about its reference) moved to ``origin``, horizontally."""
    shift = geodetic_to_ned(np.column_stack([ref_lla[:, 0], ref_lla[:, 1], np.full(len(ref_lla), origin[2])]), origin)
    out = np.array(lpos_ned, dtype=float)
    out[:, :2] += shift[:, :2]
    return out


def _log_reader(module: str, loader: str):
    """The module ``module``, which only the loaders need (``pip install "quadlib[logs]"``), or an error
    that says so."""
    package = module.split(".")[0]
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as err:
        raise ModuleNotFoundError(f"{loader}: expected the package {package!r} to read the log, got none installed; "
                                  f'install it with pip install "quadlib[logs]" (or pip install {package})',
                                  name=package) from err


def load_px4_log(log: str | os.PathLike = "px4/01_07_59.px4log") -> FlightLog:
    """Read a legacy sdlog2 ``.px4log`` (by name in the data folder, or a path) as a :class:`FlightLog`."""
    DFReader = _log_reader("pymavlink.DFReader", "load_px4_log")

    path = _resolve(log, ".px4log")
    wanted = {"IMU", "SENS", "GPS", "ATT", "LPOS"}
    parameters = {}
    rows: dict[str, list] = {k: [] for k in wanted}
    t_now = None
    reader = None
    try:
        reader = DFReader.DFReader_binary(str(path), zero_time_base=True)
        while (m := reader.recv_msg()) is not None:
            kind = m.get_type()
            if kind == "TIME":
                t_now = m.StartTime * 1e-6
            elif kind == "PARM":
                parameters.setdefault(m.Name, float(m.Value))
            elif kind in wanted and t_now is not None:
                rows[kind].append((t_now, m))
    except Exception as err:  # pymavlink raises many kinds on a damaged file
        raise _corrupt(path, "is not a readable px4log", err) from err
    finally:
        if reader is not None:
            reader.close()
    if not rows["IMU"] or not rows["ATT"]:
        raise _corrupt(path, f"holds {len(rows['IMU'])} IMU and {len(rows['ATT'])} ATT messages after a TIME message")

    def col(kind, *fields):
        return np.array([[getattr(m, f) for f in fields] for _, m in rows[kind]], dtype=float)

    def times(kind):
        return np.array([t for t, _ in rows[kind]])

    t_imu = times("IMU")
    t0 = t_imu[0]
    keep = np.r_[True, np.diff(t_imu) > 0]
    gyro, accel = col("IMU", "GyroX", "GyroY", "GyroZ"), col("IMU", "AccX", "AccY", "AccZ")
    mag = _repeats_missing(t_imu, col("IMU", "MagX", "MagY", "MagZ"))
    imu = ImuLog(t_imu[keep] - t0, gyro[keep], accel[keep], mag[keep])
    att = col("ATT", "Roll", "Pitch", "Yaw")
    attitude = Samples(times("ATT") - t0, quat_from_euler(att[:, 0], att[:, 1], att[:, 2]))

    baro = None
    if rows["SENS"]:
        alt = _repeats_missing(times("SENS"), col("SENS", "BaroAlt"))[:, 0]
        ok = ~np.isnan(alt)
        baro = Samples(times("SENS")[ok] - t0, alt[ok])

    gps = quality = origin = position = accuracy = start_utc = None
    if rows["GPS"]:
        g = col("GPS", "GPSTime", "Fix", "Lat", "Lon", "Alt", "VelN", "VelE", "VelD", "EPH", "EPV", "nSat")
        new = np.r_[True, np.any(np.diff(g[:, 2:8], axis=0) != 0, axis=1)] & (g[:, 1] >= 3)
        g, tg = g[new], times("GPS")[new] - t0
        if g.shape[0]:
            origin = g[0, 2:5].copy()
            start_utc = _utc(g[0, 0])
            gps = Samples(tg, np.column_stack([geodetic_to_ned(g[:, 2:5], origin), g[:, 5:8]]))
            quality = Samples(tg, g[:, 8:11])
            if rows["LPOS"]:
                lp = col("LPOS", "X", "Y", "Z", "VX", "VY", "VZ", "RLat", "RLon", "EPH", "EPV")
                pos = _position_in_origin(lp[:, :3], lp[:, 6:8], origin)
                position = Samples(times("LPOS") - t0, np.column_stack([pos, lp[:, 3:6]]))
                accuracy = Samples(times("LPOS") - t0, lp[:, 8:10])
    return FlightLog(name=path.name, imu=imu, baro=baro, gps=gps, gps_quality=quality, origin=origin,
                     attitude=attitude, position=position, position_accuracy=accuracy, parameters=parameters,
                     start_utc=start_utc)


def _utc(microseconds) -> datetime.datetime | None:
    """A GPS receiver's UTC time [µs since 1970] as a datetime; None where it is not known (0)."""
    if not microseconds > 0:
        return None
    return datetime.datetime.fromtimestamp(float(microseconds) * 1e-6, datetime.UTC)


_ULOG_TOPICS = ["sensor_combined", "vehicle_attitude", "vehicle_magnetometer", "sensor_mag", "vehicle_air_data",
                "sensor_baro", "vehicle_gps_position", "sensor_gps", "vehicle_local_position"]


def _sample_times_us(d) -> np.ndarray:
    """A topic's sample times [µs]: ``timestamp_sample`` where logged (and set), else ``timestamp``."""
    t = np.asarray(d["timestamp"], dtype=np.int64)
    if "timestamp_sample" in d:
        sample = np.asarray(d["timestamp_sample"], dtype=np.int64)
        t = np.where(sample > 0, sample, t)
    return t


def _on_imu_rows(t_imu_us, t_us, values) -> np.ndarray:
    """Readings ``values`` (K, m) at times ``t_us`` placed on the first IMU row at or after each, NaN
    elsewhere (N, m); of several readings on one row the last is kept, readings after the log are dropped."""
    out = np.full((t_imu_us.size, values.shape[1]), np.nan)
    row = np.searchsorted(t_imu_us, t_us, side="left")
    inside = row < t_imu_us.size
    out[row[inside]] = values[inside]
    return out


def _pressure_altitude_m(pressure_pa, qnh_pa) -> np.ndarray:
    """Altitude [m] of the standard atmosphere's troposphere at ``pressure_pa`` above the level of
    ``qnh_pa``, as PX4 computes ``baro_alt_meter``: ``T₀/L (1 − (p/p₀)^(R L/g₀))`` with T₀ = 288.15 K,
    L = 0.0065 K/m, R = 287.05 J/(kg K), g₀ = 9.80665 m/s²."""
    T0, L, R = 288.15, 0.0065, 287.05
    return T0 / L * (1.0 - (pressure_pa / qnh_pa) ** (R * L / G0))


def _columns(d, *names) -> np.ndarray:
    return np.column_stack([np.asarray(d[n], dtype=float) for n in names])


def load_ulog(log: str | os.PathLike = "px4/sample.ulg") -> FlightLog:
    """Read a ULog ``.ulg`` (by name in the data folder, or a path) as a :class:`FlightLog`.

    Reads the IMU from ``sensor_combined`` and the attitude from ``vehicle_attitude``; the
    magnetometer, barometer, GPS and the autopilot's position where the log has them, from the
    topics of old and current PX4 versions (module documentation).
    """
    ULog = _log_reader("pyulog", "load_ulog").ULog

    path = _resolve(log, ".ulg")
    try:
        ulog = ULog(str(path), _ULOG_TOPICS)
    except Exception as err:  # pyulog raises many kinds on a damaged file
        raise _corrupt(path, "is not a readable ULog", err) from err
    topics = {d.name: d.data for d in sorted(ulog.data_list, key=lambda d: d.multi_id, reverse=True)}
    for needed in ("sensor_combined", "vehicle_attitude"):
        if needed not in topics:
            raise _corrupt(path, f"has no {needed!r} topic (it has {sorted(topics)})")
    sc = topics["sensor_combined"]

    def vec(d, name, n=3):
        return _columns(d, *(f"{name}[{i}]" for i in range(n)))

    t_us = np.asarray(sc["timestamp"], dtype=np.int64)
    t0 = t_us[0]

    def seconds(t):
        return (np.asarray(t, dtype=np.int64) - t0) * 1e-6

    def reading_times(stream):  # sensor_combined's own magnetometer or barometer stream, or None
        key = f"{stream}_timestamp_relative"
        if key not in sc:
            return None
        relative = np.asarray(sc[key], dtype=np.int64)
        return None if np.all(relative == _ULOG_INVALID) else t_us + relative

    mag = None
    if (mag_t := reading_times("magnetometer")) is not None:
        mag = vec(sc, "magnetometer_ga")
        mag[np.r_[False, np.diff(mag_t) == 0]] = np.nan
    elif "vehicle_magnetometer" in topics:
        d = topics["vehicle_magnetometer"]
        mag = _on_imu_rows(t_us, _sample_times_us(d), vec(d, "magnetometer_ga"))
    elif "sensor_mag" in topics:
        d = topics["sensor_mag"]
        mag = _on_imu_rows(t_us, _sample_times_us(d), _columns(d, "x", "y", "z"))
    imu = ImuLog(seconds(t_us), vec(sc, "gyro_rad"), vec(sc, "accelerometer_m_s2"), mag)

    baro = None
    if (baro_t := reading_times("baro")) is not None:
        new = np.r_[True, np.diff(baro_t) != 0]
        baro = Samples(seconds(baro_t[new]), np.asarray(sc["baro_alt_meter"], dtype=float)[new])
    elif "vehicle_air_data" in topics:
        d = topics["vehicle_air_data"]
        baro = Samples(seconds(_sample_times_us(d)), np.asarray(d["baro_alt_meter"], dtype=float))
    elif "sensor_baro" in topics:
        d = topics["sensor_baro"]
        qnh_pa = 100.0 * float(ulog.initial_parameters.get("SENS_BARO_QNH", 1013.25))
        altitude = _pressure_altitude_m(np.asarray(d["pressure"], dtype=float), qnh_pa)
        baro = Samples(seconds(_sample_times_us(d)), altitude)
    if baro is not None:
        later = np.r_[True, np.diff(baro.t) > 0]
        baro = Samples(baro.t[later], baro.z[later].reshape(-1))

    va = topics["vehicle_attitude"]
    attitude = Samples(seconds(_sample_times_us(va)), vec(va, "q", 4))

    gps = quality = origin = position = accuracy = start_utc = None
    g = topics.get("vehicle_gps_position", topics.get("sensor_gps"))
    if g is not None:
        fix = np.asarray(g["fix_type"]) >= 3
        if fix.any():
            if "time_utc_usec" in g:
                utc = np.asarray(g["time_utc_usec"], dtype=np.int64)[fix]
                start_utc = _utc(utc[np.argmax(utc > 0)])
            if "latitude_deg" in g:  # PX4 v1.14 and later
                lla = _columns(g, "latitude_deg", "longitude_deg", "altitude_msl_m")
            else:
                lla = _columns(g, "lat", "lon", "alt") * np.array([1e-7, 1e-7, 1e-3])
            lla = lla[fix]
            origin = lla[0].copy()
            tg = seconds(_sample_times_us(g)[fix])
            vel = _columns(g, "vel_n_m_s", "vel_e_m_s", "vel_d_m_s")[fix]
            gps = Samples(tg, np.column_stack([geodetic_to_ned(lla, origin), vel]))
            quality = Samples(tg, _columns(g, "eph", "epv", "satellites_used")[fix])
    if origin is not None and "vehicle_local_position" in topics:
        lp = topics["vehicle_local_position"]
        ref = _columns(lp, "ref_lat", "ref_lon")
        ok = np.all(np.isfinite(ref), axis=1)
        if ok.any():
            tp = seconds(_sample_times_us(lp)[ok])
            ned = _position_in_origin(_columns(lp, "x", "y", "z")[ok], ref[ok], origin)
            position = Samples(tp, np.column_stack([ned, _columns(lp, "vx", "vy", "vz")[ok]]))
            accuracy = Samples(tp, _columns(lp, "eph", "epv")[ok])
    parameters = {name: float(value) for name, value in ulog.initial_parameters.items()}
    return FlightLog(name=path.name, imu=imu, baro=baro, gps=gps, gps_quality=quality, origin=origin,
                     attitude=attitude, position=position, position_accuracy=accuracy, parameters=parameters,
                     start_utc=start_utc)
