"""``python -m quadlib estimate LOG``: attitude (and, with GPS, position) from a sensor log.

Reads a PX4 ULog (``.ulg``), an older PX4 log (``.px4log``), a BROAD trial (``.hdf5``) or a CSV
file, runs the orientation filter (:func:`quadlib.attitude.orientation_run`) or, when the log has
GPS, the inertial navigation EKF (:func:`quadlib.nav.estimate_ins`), and writes the estimates as
CSV and, on request, a figure against the log's own reference (the autopilot's estimate, or
BROAD's optical truth).

A CSV log has a header row and the columns ``t, gyr_x, gyr_y, gyr_z, acc_x, acc_y, acc_z`` and,
optionally, ``mag_x, mag_y, mag_z``: time [s], gyro [rad/s], specific force [m/s²] and the
magnetic field (any unit), in the sensor's FRD frame, one row per IMU sample; the gyro row at
``t`` is the rate over the interval that ends at ``t``, as
:func:`quadlib.attitude.estimate_orientation` takes raw arrays; empty or NaN fields are missing
samples.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from quadlib.samples import Samples

__all__ = ["main"]

CSV_COLUMNS = ("t", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z")
MAG_COLUMNS = ("mag_x", "mag_y", "mag_z")


def read_log(path: Path):
    """``(imu, flight, reference)``: the IMU log, the PX4 log (or None) and the reference attitude
    as :class:`~quadlib.Samples` of ``q_nb`` (or None)."""
    from quadlib.data import load_broad_trial, load_px4_log, load_ulog
    from quadlib.imu import ImuLog, rates_to_interval_start

    if not path.is_file():
        raise FileNotFoundError(f"LOG: no such file: {path}")
    suffix = path.suffix.lower()
    if suffix in (".ulg", ".px4log"):
        flight = (load_ulog if suffix == ".ulg" else load_px4_log)(path)
        return flight.imu, flight, flight.attitude
    if suffix in (".hdf5", ".h5"):
        trial = load_broad_trial(path)
        return trial.log, None, Samples(trial.log.t, trial.q_nb)
    if suffix == ".csv":
        with path.open() as f:
            header = [name.strip() for name in f.readline().split(",")]
        missing = [c for c in CSV_COLUMNS if c not in header]
        if missing:
            raise ValueError(f"LOG: expected a CSV header with {', '.join(CSV_COLUMNS)} "
                             f"[, {', '.join(MAG_COLUMNS)}], got {header} (missing {missing})")
        data = np.genfromtxt(path, delimiter=",", skip_header=1, dtype=float, ndmin=2)
        col = {name: data[:, header.index(name)] for name in header if name}
        stack = lambda names: np.column_stack([col[n] for n in names])  # noqa: E731
        mag = stack(MAG_COLUMNS) if all(c in col for c in MAG_COLUMNS) else None
        gyro = rates_to_interval_start(stack(CSV_COLUMNS[1:4]))
        return ImuLog(col["t"], gyro, stack(CSV_COLUMNS[4:7]), mag), None, None
    raise ValueError(f"LOG: expected a .ulg, .px4log, .hdf5 or .csv file, got {path.name!r}")


def reference_at(reference: Samples, t: np.ndarray) -> np.ndarray:
    """The reference attitude at times ``t``: the two neighbouring samples interpolated and
    normalised (NaN outside its span and where a neighbour is missing)."""
    q = np.asarray(reference.z, dtype=float)
    i = np.clip(np.searchsorted(reference.t, t), 1, len(reference.t) - 1)
    w = ((t - reference.t[i - 1]) / (reference.t[i] - reference.t[i - 1]))[:, None]
    q0, q1 = q[i - 1], q[i]
    q1 = np.where(np.sum(q0 * q1, axis=1, keepdims=True) < 0, -q1, q1)
    out = (1 - w) * q0 + w * q1
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    out[(t < reference.t[0]) | (t > reference.t[-1])] = np.nan
    return out


def log_declination(imu, flight) -> tuple[float, str]:
    """``(declination_rad, where it came from)`` when none is given: the log's ``EKF2_MAG_DECL``,
    else the World Magnetic Model's at the log's first GPS fix and its date, else 0 (with a warning
    when there is a magnetometer: the heading is then magnetic)."""
    if flight is not None and flight.mag_declination_rad is not None:
        return flight.mag_declination_rad, "the log's EKF2_MAG_DECL"
    if flight is not None and flight.model_declination_rad is not None:
        return flight.model_declination_rad, "the World Magnetic Model at the first GPS fix"
    if imu.mag is not None and np.isfinite(imu.mag).any():
        warnings.warn("no declination given and none in the log: the heading is magnetic "
                      "(pass --declination DEG for true north)", stacklevel=3)
    return 0.0, "none known: magnetic north"


def estimate(imu, flight, *, offline: bool, declination_rad: float | None):
    """``(run, kind, declination_rad, source)``: the filter run, ``"ins"`` or ``"orientation"``, the
    declination used and where it came from (:func:`log_declination` when ``declination_rad`` is None)."""
    from quadlib.attitude import OrientationParams, orientation_run
    from quadlib.nav import InsParams, estimate_ins

    source = "given"
    if declination_rad is None:
        declination_rad, source = log_declination(imu, flight)
    if flight is not None and flight.gps is not None:
        params = InsParams()
        if flight.gps_delay_s is not None:
            params = replace(params, gps_delay_s=flight.gps_delay_s)
        run = estimate_ins(imu, flight.gps, flight.baro, params, offline=offline, declination_rad=declination_rad)
        return run, "ins", declination_rad, source
    return orientation_run(imu, OrientationParams(), offline=offline, declination_rad=declination_rad), \
        "orientation", declination_rad, source


def table(run, kind: str) -> tuple[list[str], np.ndarray]:
    """The CSV's column names and rows: time, q_nb, Euler angles [deg], gyro bias [rad/s], the
    attitude's σ [deg] and, for the INS, velocity, position and their σ."""
    from quadlib.geometry import quat_to_euler

    q = run.q
    euler = np.degrees(np.column_stack(quat_to_euler(q / np.linalg.norm(q, axis=1, keepdims=True))))
    sigma = np.sqrt(np.maximum(np.diagonal(run.P, axis1=1, axis2=2), 0.0))
    names = ["t", "qw", "qx", "qy", "qz", "roll_deg", "pitch_deg", "yaw_deg",
             "bias_x_rad_s", "bias_y_rad_s", "bias_z_rad_s", "sigma_roll_deg", "sigma_pitch_deg", "sigma_yaw_deg"]
    columns = [run.t[:, None], q, euler, run.gyro_bias, np.degrees(sigma[:, :3])]
    if kind == "ins":
        names += ["vn", "ve", "vd", "pn", "pe", "pd", "sigma_vn", "sigma_ve", "sigma_vd",
                  "sigma_pn", "sigma_pe", "sigma_pd"]
        columns += [run.v, run.p, sigma[:, 3:9]]
    return names, np.hstack(columns)


def compare(run, kind: str, reference, flight) -> list[str]:
    """Lines that say how far the estimate is from the log's own reference."""
    from quadlib.analysis import attitude_error

    lines = []
    if reference is not None:
        q_ref = reference_at(reference, run.t)
        ok = np.isfinite(q_ref).all(axis=1) & np.isfinite(run.q).all(axis=1)
        q = run.q[ok] / np.linalg.norm(run.q[ok], axis=1, keepdims=True)
        err = np.degrees(attitude_error(q, q_ref[ok]))
        lines.append(f"attitude against the log's reference: {np.sqrt(np.mean(err**2)):.2f}° RMS, "
                     f"{err.max():.2f}° at most, over {ok.sum()} samples")
    if kind == "ins" and flight.position is not None:
        p_ref = np.column_stack([np.interp(run.t, flight.position.t, flight.position.z[:, k]) for k in range(3)])
        horizontal = np.linalg.norm(run.p[:, :2] - p_ref[:, :2], axis=1)
        lines.append(f"horizontal position against the autopilot's: {np.sqrt(np.nanmean(horizontal**2)):.2f} m RMS")
    return lines


def sensor_use(run) -> list[str]:
    """One line per update: how many samples it applied, how many the χ² gate refused, and how
    often a lock-out was reset (samples the filter never had, or skipped as implausible, are not
    counted)."""
    return [f"{name}: {int(trace.used.sum())} updates, {int(trace.rejected.sum())} refused by the gate, "
            f"{int(trace.reset.sum())} resets" for name, trace in run.sensors.items()]


def plot(path: Path, run, kind: str, reference, flight) -> None:
    """Euler angles (and, for the INS, position) against the reference, to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from quadlib.geometry import quat_to_euler

    names, rows = table(run, kind)
    rows_ref = None
    if reference is not None:
        q_ref = reference_at(reference, run.t)
        ok = np.isfinite(q_ref).all(axis=1)
        rows_ref = np.full((len(run.t), 3), np.nan)
        rows_ref[ok] = np.degrees(np.column_stack(quat_to_euler(q_ref[ok])))
    panels = 6 if kind == "ins" else 3
    fig = Figure(figsize=(9, 1.8 * panels), layout="constrained")
    axes = fig.subplots(panels, 1, sharex=True)
    for k, label in enumerate(("roll [deg]", "pitch [deg]", "yaw [deg]")):
        axes[k].plot(run.t, rows[:, 5 + k], lw=1, label="estimate")
        if rows_ref is not None:
            axes[k].plot(run.t, rows_ref[:, k], lw=1, ls="--", label="reference")
        axes[k].set_ylabel(label)
    if kind == "ins":
        for k, label in enumerate(("north [m]", "east [m]", "down [m]")):
            axes[3 + k].plot(run.t, run.p[:, k], lw=1, label="estimate")
            if flight.position is not None:
                axes[3 + k].plot(flight.position.t, flight.position.z[:, k], lw=1, ls="--", label="autopilot")
            axes[3 + k].set_ylabel(label)
    axes[0].legend(loc="upper right")
    axes[-1].set_xlabel("time [s]")
    axes[0].set_title(f"{kind} estimate against the log's reference" if rows_ref is not None else f"{kind} estimate")
    fig.savefig(path, dpi=100)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m quadlib", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    est = sub.add_parser("estimate", help="attitude (and position, with GPS) from a sensor log")
    est.add_argument("log", type=Path, help=".ulg, .px4log, .hdf5 (BROAD) or .csv")
    est.add_argument("--offline", action="store_true", help="smooth with the backward pass (post-flight)")
    est.add_argument("--declination", type=float, default=None, metavar="DEG",
                     help="magnetic declination, east of true north [deg] (default: the log's EKF2_MAG_DECL, else "
                          "the World Magnetic Model's at the first GPS fix, else 0)")
    est.add_argument("--out", type=Path, default=Path("estimates.csv"), help="CSV to write (default estimates.csv)")
    est.add_argument("--plot", type=Path, default=None, metavar="PNG", help="figure to write")
    args = parser.parse_args(argv)

    from quadlib.progress import progress

    declination = None if args.declination is None else float(np.radians(args.declination))
    steps = iter(progress(range(3), f"estimate {args.log.name}"))
    try:
        next(steps)
        imu, flight, reference = read_log(args.log)
        next(steps)
        run, kind, declination, source = estimate(imu, flight, offline=args.offline, declination_rad=declination)
        next(steps)
    except (FileNotFoundError, ValueError, TypeError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    names, rows = table(run, kind)
    np.savetxt(args.out, rows, delimiter=",", header=",".join(names), comments="", fmt="%.9g")
    print(f"{args.log.name}: {len(imu)} IMU samples over {imu.t[-1] - imu.t[0]:.1f} s, {kind} filter"
          f"{' (smoothed)' if args.offline else ''}, declination {np.degrees(declination):.2f}° ({source})")
    for line in compare(run, kind, reference, flight) + sensor_use(run):
        print(line)
    print(f"wrote {args.out}")
    if args.plot is not None:
        plot(args.plot, run, kind, reference, flight)
        print(f"wrote {args.plot}")
    return 0
