"""``python -m quadlib estimate``: on the shipped logs, through a CSV, and with bad input."""

import subprocess
import sys

import numpy as np
import pytest

from quadlib.attitude import OrientationParams, orientation_run
from quadlib.cli import main
from quadlib.data import data_path, load_broad_trial


def _read(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    return names, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def test_a_ulog_without_gps_gets_the_orientation_filter_and_agrees_with_px4(tmp_path, capsys):
    out, png = tmp_path / "est.csv", tmp_path / "est.png"
    with pytest.warns(UserWarning, match="no declination given and none in the log"):
        assert main(["estimate", str(data_path("px4/sample.ulg")), "--out", str(out), "--plot", str(png)]) == 0
    printed = capsys.readouterr().out
    assert "orientation filter" in printed
    heading = next(line for line in printed.splitlines() if line.startswith("heading: "))
    assert int(heading.split("heading: ")[1].split(" updates")[0]) > 1000 and heading.endswith(" resets")
    rms = float(printed.split("reference: ")[1].split("°")[0])
    assert rms < 1.0
    names, rows = _read(out)
    assert names[:8] == ["t", "qw", "qx", "qy", "qz", "roll_deg", "pitch_deg", "yaw_deg"]
    assert "pn" not in names
    assert np.allclose(np.linalg.norm(rows[:, 1:5], axis=1), 1.0, atol=1e-6)
    assert png.stat().st_size > 10_000


def test_a_ulog_with_gps_gets_the_ins_and_its_position_columns(tmp_path, capsys):
    out = tmp_path / "est.csv"
    assert main(["estimate", str(data_path("px4/sample_px4_events.ulg")), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "ins filter" in printed
    horizontal = float(printed.split("autopilot's: ")[1].split(" m")[0])
    assert horizontal < 0.5
    names, rows = _read(out)
    assert names[-12:-9] == ["vn", "ve", "vd"] and "sigma_pd" in names
    assert np.isfinite(rows).all()


def test_a_log_without_a_declination_takes_the_field_models_at_its_first_fix(tmp_path, capsys):
    """The 2015 px4log logs no declination: the World Magnetic Model's −4.08° at its first fix
    brings the attitude from 6.6° RMS off the autopilot's (magnetic north taken as true) to 3.6°; the
    rest is mostly the autopilot's own north, about 2° further west (chapter 17 measures it)."""
    assert main(["estimate", str(data_path("px4/01_07_59.px4log")), "--out", str(tmp_path / "e.csv")]) == 0
    printed = capsys.readouterr().out
    assert "declination -4.08° (the World Magnetic Model at the first GPS fix)" in printed
    assert float(printed.split("reference: ")[1].split("°")[0]) < 4.0


def test_a_csv_of_broads_raw_arrays_gives_what_the_loaded_trial_gives(tmp_path):
    import h5py

    name, n = "02_undisturbed_slow_rotation_B", 3000
    with h5py.File(data_path(f"broad/{name}.hdf5"), "r") as f:
        rate = float(f.attrs["sampling_rate"])
        gyr, acc, mag = (np.asarray(f[k], dtype=float)[:n] for k in ("imu_gyr", "imu_acc", "imu_mag"))
    csv = tmp_path / "imu.csv"
    np.savetxt(csv, np.column_stack([np.arange(n) / rate, gyr, acc, mag]), delimiter=",", fmt="%.17g", comments="",
               header="t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z")
    out = tmp_path / "est.csv"
    assert main(["estimate", str(csv), "--out", str(out), "--declination", "10"]) == 0
    _, rows = _read(out)
    expected = orientation_run(load_broad_trial(name).log.slice(0, n), OrientationParams(),
                               declination_rad=np.radians(10.0))
    assert rows.shape[0] == n
    # the last row differs: the loaded slice knows the rate after it, the CSV does not
    assert np.allclose(rows[:-1, 1:5], expected.x[:-1, :4], atol=1e-8)


def test_bad_input_gets_a_message_and_exit_status_2(tmp_path, capsys):
    assert main(["estimate", str(tmp_path / "nowhere.ulg")]) == 2
    assert "no such file" in capsys.readouterr().err
    bad = tmp_path / "bad.csv"
    bad.write_text("time,gx,gy,gz\n0,0,0,0\n")
    assert main(["estimate", str(bad), "--out", str(tmp_path / "o.csv")]) == 2
    err = capsys.readouterr().err
    assert "LOG: expected a CSV header with t, gyr_x" in err and "missing" in err
    other = tmp_path / "log.txt"
    other.write_text("x")
    assert main(["estimate", str(other)]) == 2
    assert ".ulg, .px4log, .hdf5 or .csv" in capsys.readouterr().err


def test_the_module_runs_as_a_command():
    done = subprocess.run([sys.executable, "-m", "quadlib", "estimate", "--help"], capture_output=True, text=True)
    assert done.returncode == 0 and "--declination DEG" in done.stdout


@pytest.mark.parametrize("name", ["estimate_orientation", "estimate_ins"])
def test_the_estimators_are_importable_from_quadlib(name):
    import quadlib

    assert callable(getattr(quadlib, name)) and name in quadlib.__all__
