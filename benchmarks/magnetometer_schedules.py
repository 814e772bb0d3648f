"""The orientation filter when the magnetometer does not start with the log.

Usage: ``python benchmarks/magnetometer_schedules.py [FIRST_FIELD_S | none]`` (about 20 s on 2 cores).
On each of BROAD's ten trials, with the defaults (the MEKF's ``OrientationParams.mag_first_field_s``
set to ``FIRST_FIELD_S`` when given, ``none``: off), the MEKF's and VQF's total error [deg] over the
scored motion, the field given to both as:

* ``as logged``;
* ``from motion``: no reading before the first second of scored motion plus 10 s, so the first
  reading comes while the board moves;
* ``magnet at start``: the first 3 s of readings 1.5 times too strong (a magnet beside the start),
  so the first reading's field is the wrong reference;
* ``VQF's flags``: every reading VQF's own detector calls disturbed (``magDistDetected``) left out,
  which on some trials is everything up to the tens of seconds its first new field takes.

Printed: per trial and schedule ``MEKF / VQF``, and per schedule the mean and the worst ratio.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from multiprocessing import Pool

import numpy as np

from quadlib.analysis.metrics import broad_errors
from quadlib.analysis.orientation_table import _arrays, orientation_estimate
from quadlib.attitude import OrientationParams, estimate_orientation
from quadlib.data import broad_trial_names, load_broad_trial

SCHEDULES = ("as logged", "from motion", "magnet at start", "VQF's flags")


def field(schedule: str, log, movement) -> np.ndarray:
    """The magnetometer ``(N, 3)`` under ``schedule`` (NaN rows: no reading)."""
    if schedule == "as logged":
        return log.mag
    if schedule == "from motion":
        return np.where((log.t < log.t[np.argmax(movement)] + 10.0)[:, None], np.nan, log.mag)
    if schedule == "magnet at start":
        return np.where((log.t < log.t[0] + 3.0)[:, None], 1.5, 1.0) * log.mag
    import vqf

    Ts, gyr, acc, mag = _arrays(log)
    disturbed = vqf.VQF(Ts).updateBatch(gyr, acc, mag)["magDistDetected"].astype(bool)
    return np.where(disturbed[:, None], np.nan, log.mag)


def one_trial(job: tuple[str, OrientationParams]) -> tuple[str, list[tuple[float, float]]]:
    name, params = job
    trial = load_broad_trial(name)
    scores = []
    for schedule in SCHEDULES:
        log = replace(trial.log, mag=field(schedule, trial.log, trial.movement))
        mekf = broad_errors(estimate_orientation(log, params=params).q, trial.q_nb, trial.movement)["total_deg"]
        as_vqf = replace(log, mag=np.nan_to_num(log.mag, nan=0.0))  # VQF skips a zero reading, and a NaN spoils it
        vqf = broad_errors(orientation_estimate("VQF", as_vqf), trial.q_nb, trial.movement)["total_deg"]
        scores.append((mekf, vqf))
    return name, scores


def main(first_field_s: str | None = None) -> None:
    import warnings

    warnings.simplefilter("ignore", UserWarning)  # a run that used few headings says so; the table shows it
    params = OrientationParams() if first_field_s is None else OrientationParams(
        mag_first_field_s=None if first_field_s == "none" else float(first_field_s))
    with Pool(2) as pool:
        done = pool.map(one_trial, [(name, params) for name in broad_trial_names()], chunksize=1)
    print("BROAD's ten trials, the magnetometer on four schedules; total error [deg], MEKF / VQF"
          + f" (MEKF's mag_first_field_s: {params.mag_first_field_s})")
    print(f"{'trial':<6}" + "".join(f" | {s:>15}" for s in SCHEDULES))
    for name, scores in done:
        print(f"{name[:2]:<6}" + "".join(f" | {m:6.2f} / {v:6.2f}" for m, v in scores))
    ratios = np.array([[m / v for m, v in scores] for _, scores in done])
    means = np.array([[[m, v] for m, v in scores] for _, scores in done]).mean(axis=0)
    print(f"{'mean':<6}" + "".join(f" | {m:6.2f} / {v:6.2f}" for m, v in means))
    print(f"{'worst':<6}" + "".join(f" | {r:15.2f}" for r in ratios.max(axis=0)) + "   (MEKF / VQF, worst trial)")


if __name__ == "__main__":
    main(*sys.argv[1:2])
