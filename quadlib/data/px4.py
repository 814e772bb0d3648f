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
* ``.ulg`` (read with pyulog): ``sensor_combined`` holds gyro and accelerometer at the IMU's rate and
  the latest magnetometer and barometer readings with their own relative timestamps; a reading
  whose timestamp did not change is marked missing, and a stream whose relative timestamp is the
  "invalid" marker 2³¹ − 1 throughout (no such sensor) is left out.

The autopilot's attitude is ``ATT`` (roll, pitch, yaw; the quaternion fields of this log version
are zero) or ``vehicle_attitude`` (a quaternion); its position ``LPOS`` is NED about its own
reference point, which is moved to this log's origin so the two can be compared.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from quadlib.data.paths import SOURCES, DataCorruptError, data_path
from quadlib.geometry.geodetic import geodetic_to_ned
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


def _resolve(log: str | os.PathLike, suffix: str) -> Path:
    if not isinstance(log, (str, os.PathLike)):
        raise TypeError(f"log: expected a file name such as 'px4/sample.ulg' or a path, got {type(log).__name__}")
    path = Path(log)
    if path.suffix != suffix:
        raise ValueError(f"log: expected a {suffix} file, got {str(log)!r}")
    if path.is_absolute() or path.is_file():
        if not path.is_file():
            return data_path(f"px4/{path.name}")  # not there: the error names it and its source
        return path
    return data_path(path.as_posix() if path.parent.name == "px4" else f"px4/{path.name}")


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


def load_px4_log(log: str | os.PathLike = "px4/01_07_59.px4log") -> FlightLog:
    """Read a legacy sdlog2 ``.px4log`` (by name in the data folder, or a path) as a :class:`FlightLog`."""
    from pymavlink import DFReader  # only the loaders need it

    path = _resolve(log, ".px4log")
    wanted = {"IMU", "SENS", "GPS", "ATT", "LPOS"}
    rows: dict[str, list] = {k: [] for k in wanted}
    t_now = None
    reader = None
    try:
        reader = DFReader.DFReader_binary(str(path), zero_time_base=True)
        while (m := reader.recv_msg()) is not None:
            kind = m.get_type()
            if kind == "TIME":
                t_now = m.StartTime * 1e-6
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

    gps = quality = origin = position = accuracy = None
    if rows["GPS"]:
        g = col("GPS", "GPSTime", "Fix", "Lat", "Lon", "Alt", "VelN", "VelE", "VelD", "EPH", "EPV", "nSat")
        new = np.r_[True, np.any(np.diff(g[:, 2:8], axis=0) != 0, axis=1)] & (g[:, 1] >= 3)
        g, tg = g[new], times("GPS")[new] - t0
        if g.shape[0]:
            origin = g[0, 2:5].copy()
            gps = Samples(tg, np.column_stack([geodetic_to_ned(g[:, 2:5], origin), g[:, 5:8]]))
            quality = Samples(tg, g[:, 8:11])
            if rows["LPOS"]:
                lp = col("LPOS", "X", "Y", "Z", "VX", "VY", "VZ", "RLat", "RLon", "EPH", "EPV")
                pos = _position_in_origin(lp[:, :3], lp[:, 6:8], origin)
                position = Samples(times("LPOS") - t0, np.column_stack([pos, lp[:, 3:6]]))
                accuracy = Samples(times("LPOS") - t0, lp[:, 8:10])
    return FlightLog(name=path.name, imu=imu, baro=baro, gps=gps, gps_quality=quality, origin=origin,
                     attitude=attitude, position=position, position_accuracy=accuracy)


def load_ulog(log: str | os.PathLike = "px4/sample.ulg") -> FlightLog:
    """Read a ULog ``.ulg`` (by name in the data folder, or a path) as a :class:`FlightLog`.

    Reads ``sensor_combined`` and ``vehicle_attitude``; GPS and the autopilot's position are read
    from ``vehicle_gps_position`` and ``vehicle_local_position`` when the log has them.
    """
    from pyulog import ULog  # only the loaders need it

    path = _resolve(log, ".ulg")
    try:
        ulog = ULog(str(path), ["sensor_combined", "vehicle_attitude", "vehicle_gps_position",
                                "vehicle_local_position"])
    except Exception as err:  # pyulog raises many kinds on a damaged file
        raise _corrupt(path, "is not a readable ULog", err) from err
    topics = {d.name: d.data for d in ulog.data_list if d.multi_id == 0}
    for needed in ("sensor_combined", "vehicle_attitude"):
        if needed not in topics:
            raise _corrupt(path, f"has no {needed!r} topic (it has {sorted(topics)})")
    sc = topics["sensor_combined"]

    def vec(d, field, n=3):
        return np.column_stack([np.asarray(d[f"{field}[{i}]"], dtype=float) for i in range(n)])

    t_us = np.asarray(sc["timestamp"], dtype=np.int64)
    t0 = t_us[0]

    def reading_times(field):  # absolute times of a stream's readings, or None when it has none
        relative = np.asarray(sc[f"{field}_timestamp_relative"], dtype=np.int64)
        return None if np.all(relative == _ULOG_INVALID) else t_us + relative

    mag = None
    if (mag_t := reading_times("magnetometer")) is not None:
        mag = vec(sc, "magnetometer_ga")
        mag[np.r_[False, np.diff(mag_t) == 0]] = np.nan
    imu = ImuLog((t_us - t0) * 1e-6, vec(sc, "gyro_rad"), vec(sc, "accelerometer_m_s2"), mag)
    baro = None
    if (baro_t := reading_times("baro")) is not None:
        new = np.r_[True, np.diff(baro_t) != 0]
        baro = Samples((baro_t[new] - t0) * 1e-6, np.asarray(sc["baro_alt_meter"], dtype=float)[new])
    va = topics["vehicle_attitude"]
    attitude = Samples((np.asarray(va["timestamp"], dtype=np.int64) - t0) * 1e-6, vec(va, "q", 4))

    gps = quality = origin = position = None
    if "vehicle_gps_position" in topics:
        g = topics["vehicle_gps_position"]
        fix = np.asarray(g["fix_type"]) >= 3
        if fix.any():
            lla = np.column_stack([np.asarray(g["lat"]) * 1e-7, np.asarray(g["lon"]) * 1e-7,
                                   np.asarray(g["alt"]) * 1e-3])[fix]
            origin = lla[0].copy()
            tg = (np.asarray(g["timestamp"], dtype=np.int64)[fix] - t0) * 1e-6
            vel = np.column_stack([np.asarray(g[k], dtype=float) for k in ("vel_n_m_s", "vel_e_m_s", "vel_d_m_s")])
            gps = Samples(tg, np.column_stack([geodetic_to_ned(lla, origin), vel[fix]]))
            quality = Samples(tg, np.column_stack([np.asarray(g[k], dtype=float)[fix]
                                                   for k in ("eph", "epv", "satellites_used")]))
    if origin is not None and "vehicle_local_position" in topics:
        lp = topics["vehicle_local_position"]
        ned = np.column_stack([np.asarray(lp[k], dtype=float) for k in ("x", "y", "z")])
        ref = np.column_stack([np.asarray(lp["ref_lat"], dtype=float), np.asarray(lp["ref_lon"], dtype=float)])
        vel = np.column_stack([np.asarray(lp[k], dtype=float) for k in ("vx", "vy", "vz")])
        position = Samples((np.asarray(lp["timestamp"], dtype=np.int64) - t0) * 1e-6,
                           np.column_stack([_position_in_origin(ned, ref, origin), vel]))
    return FlightLog(name=path.name, imu=imu, baro=baro, gps=gps, gps_quality=quality, origin=origin,
                     attitude=attitude, position=position)
