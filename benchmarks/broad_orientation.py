"""Orientation on the BROAD trials: every quadlib estimator against VQF and ahrs, in one run.

Usage: ``python benchmarks/broad_orientation.py [estimator,estimator,...]`` (all of them: about
7 minutes on 2 cores, most of it the fixed-wing error-state UKF; named ones replace their rows in
the stored results and keep the others). Prints, per trial and as the mean
over the trials, BROAD's total / heading / inclination RMSE [deg] (Laidig et al. 2021;
:func:`quadlib.analysis.broad_errors`) and the cost per sample [µs] of each estimator, all with
default parameters (no per-trial tuning), and writes them to ``benchmarks/results/
broad_orientation.csv``, the table chapter 16 shows.

The estimators and their frame conversions are :mod:`quadlib.analysis.orientation_table`'s. The
check that the frames are right: VQF reproduces its published means on these trials (2.74° /
2.64° / 0.56°, offline 1.75°). ahrs's EKF is left out: no frame and sign convention made its
output match the truth on a slow trial.
"""

from __future__ import annotations

import csv
import sys
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from quadlib.analysis.orientation_table import error_components, estimator_names, score_estimators
from quadlib.data import broad_trial_names, load_broad_trial

RESULTS = Path(__file__).resolve().parent / "results" / "broad_orientation.csv"
SERIES = RESULTS.with_name("broad_error_series.csv")
COLUMNS = ("total_deg", "heading_deg", "inclination_deg", "us_per_sample")
SERIES_HZ = 2.0  # the error series chapter 16 plots: these trials and estimators, two samples a second
SERIES_TRIALS = ("02_undisturbed_slow_rotation_B", "24_disturbed_tapping_A", "32_disturbed_attached_magnet_1cm")
SERIES_ESTIMATORS = ("quadlib MEKF", "quadlib MEKF smoother", "Kesten TQF", "Kesten QKF", "Salmony EKF", "VQF",
                     "offline VQF", "ahrs Madgwick")


def one_trial(args):
    name, estimators = args
    trial = load_broad_trial(name)
    rows, estimates = score_estimators(estimators, trial.log, trial.q_nb, trial.movement)
    every = max(1, int(round(1.0 / (SERIES_HZ * float(np.median(trial.log.dt))))))
    series = {k: tuple(c[::every] for c in error_components(q, trial.q_nb)) for k, q in estimates.items()
              if name in SERIES_TRIALS and k in SERIES_ESTIMATORS}
    return name, (rows, trial.log.t[::every], series)


def _write_merged(path: Path, header, rows, estimators) -> None:
    """Write ``rows``, keeping the rows of the estimators not re-run from the file's last version."""
    kept = []
    if path.is_file():
        with path.open(newline="") as f:
            kept = [tuple(r) for r in list(csv.reader(f))[1:] if r[1] not in estimators]
    order = {name: i for i, name in enumerate(estimator_names())}
    merged = sorted(kept + rows, key=lambda r: (r[0], order.get(r[1], len(order))))  # stable: time order kept
    with path.open("w", newline="") as f:
        out = csv.writer(f)
        out.writerow(header)
        out.writerows(merged)


def main(estimators) -> None:
    with Pool(2) as pool:
        done = dict(pool.map(one_trial, [(name, estimators) for name in broad_trial_names()], chunksize=1))
    results = {trial: rows for trial, (rows, _, _) in done.items()}
    RESULTS.parent.mkdir(exist_ok=True)
    series_rows = [(trial, name) + tuple(f"{v:.3f}" for v in row)
                   for trial, (_, t, series) in done.items() for name, (heading, inclination) in series.items()
                   for row in zip(t, heading, inclination, strict=True)]
    result_rows = [(trial, name) + tuple(f"{row[c]:.4f}" for c in COLUMNS)
                   for trial, rows in results.items() for name, row in rows.items()]
    _write_merged(SERIES, ("trial", "estimator", "t_s", "heading_error_deg", "inclination_error_deg"), series_rows,
                  estimators)
    _write_merged(RESULTS, ("trial", "estimator") + COLUMNS, result_rows, estimators)
    print("total / heading / inclination RMSE [deg], mean over the trials; cost [µs per sample]")
    print(f"| estimator | {' | '.join(t[:2] for t in results)} | **mean** | µs per sample |")
    print("|---|" + "---|" * (len(results) + 2))
    for name in estimators:
        cells = [results[t][name] for t in results]
        mean = {c: np.mean([r[c] for r in cells]) for c in COLUMNS}
        print(f"| {name} | " + " | ".join("{total_deg:.2f} / {heading_deg:.2f} / {inclination_deg:.2f}".format(**r)
                                         for r in cells)
              + " | **{total_deg:.2f} / {heading_deg:.2f} / {inclination_deg:.2f}** | {us_per_sample:.1f} |".format(
                  **mean))
    print(f"written: {RESULTS}")


if __name__ == "__main__":
    main(sys.argv[1].split(",") if len(sys.argv) > 1 else estimator_names())
