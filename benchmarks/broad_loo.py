"""How the orientation MEKF's settings were chosen, and how it does on trials it was not tuned on.

Usage: ``python benchmarks/broad_loo.py`` (about 12 minutes on 2 cores). Leave-one-trial-out over
the ten BROAD trials the project ships: every setting of a small grid — the gravity update's σ
(``gravity_sigma_m_s2``), the low-pass's τ (``accel_tau_s``), the heading update
(``tilt_aware_heading``), the gyro bias's random walk (``gyro_bias_walk_rad_s_sqrt_s``) and how far
the field's strength may stray (``checks.mag_norm_tolerance``), and whether the output's tilt is
refined toward the averaged gravity's (``tilt_refinement_deg`` 4° or None) — is scored on every trial; for each
trial in turn, the setting with the lowest mean total error on the other nine is chosen and scored
on the one left out. Prints the in-sample grid and the held-out table against VQF (BROAD's errors
[deg], :func:`quadlib.analysis.broad_errors`), and writes both to ``benchmarks/results/broad_loo.csv``.
The defaults of :class:`~quadlib.attitude.OrientationParams` are the setting every fold but at most
a few chose.
"""

from __future__ import annotations

import csv
import itertools
from dataclasses import replace
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from quadlib.analysis.metrics import broad_errors
from quadlib.analysis.orientation_table import orientation_estimate
from quadlib.attitude import OrientationParams, SensorChecks, estimate_orientation
from quadlib.data import broad_trial_names, load_broad_trial

RESULTS = Path(__file__).resolve().parent / "results" / "broad_loo.csv"
GRID = [dict(gravity_sigma_m_s2=s, accel_tau_s=tau, tilt_aware_heading=tilt, gyro_bias_walk_rad_s_sqrt_s=walk,
             checks=SensorChecks(mag_norm_tolerance=tol), tilt_refinement_deg=width)
        for s, tau, tilt, walk, tol, width in itertools.product((0.3, 0.5, 1.0), (1.5, 3.0), (True, False),
                                                                (1e-4, 3e-5), (0.2, 0.1, 0.05), (4.0, None))]
COLUMNS = ("total_deg", "heading_deg", "inclination_deg")


def label(setting: dict) -> str:
    heading = "tilt-aware" if setting["tilt_aware_heading"] else "heading-only"
    return (f"σ_f {setting['gravity_sigma_m_s2']:g}, τ {setting['accel_tau_s']:g} s, {heading}, "
            f"bias walk {setting['gyro_bias_walk_rad_s_sqrt_s']:g}, field ±{setting['checks'].mag_norm_tolerance:.0%}, "
            f"{'tilt refined' if setting['tilt_refinement_deg'] else 'filter tilt'}")


def one_trial(name: str) -> tuple[str, list, tuple]:
    trial = load_broad_trial(name)
    scores = []
    for setting in GRID:
        e = broad_errors(estimate_orientation(trial.log, params=replace(OrientationParams(), **setting)).q,
                         trial.q_nb, trial.movement)
        scores.append(tuple(e[c] for c in COLUMNS))
    vqf = broad_errors(orientation_estimate("VQF", trial.log), trial.q_nb, trial.movement)
    return name, scores, tuple(vqf[c] for c in COLUMNS)


def main() -> None:
    with Pool(2) as pool:
        done = pool.map(one_trial, broad_trial_names(), chunksize=1)
    names = [n for n, _, _ in done]
    score = {n: np.array(s) for n, s, _ in done}  # (settings, 3) per trial
    vqf = {n: np.array(v) for n, _, v in done}
    rows = []
    print("in-sample: mean over the ten trials, total / heading / inclination [deg]")
    for i, setting in enumerate(GRID):
        m = np.mean([score[n][i] for n in names], axis=0)
        print(f"  {label(setting):<40} {m[0]:.2f} / {m[1]:.2f} / {m[2]:.2f}")
        rows += [("in-sample", n, label(setting)) + tuple(f"{v:.4f}" for v in score[n][i]) for n in names]
    print("\nheld out: each trial scored with the setting chosen on the other nine (lowest mean total)")
    print("| trial | chosen | MEKF | VQF | ratio (total) |\n|---|---|---|---|---|")
    held = []
    for n in names:
        others = [o for o in names if o != n]
        best = int(np.argmin([np.mean([score[o][i][0] for o in others]) for i in range(len(GRID))]))
        e = score[n][best]
        held.append(e)
        rows.append(("held-out", n, label(GRID[best])) + tuple(f"{v:.4f}" for v in e))
        rows.append(("VQF", n, "defaults") + tuple(f"{v:.4f}" for v in vqf[n]))
        print(f"| {n[:2]} | {label(GRID[best])} | {e[0]:.2f} / {e[1]:.2f} / {e[2]:.2f} | "
              f"{vqf[n][0]:.2f} / {vqf[n][1]:.2f} / {vqf[n][2]:.2f} | {e[0] / vqf[n][0]:.2f} |")
    m, v = np.mean(held, axis=0), np.mean([vqf[n] for n in names], axis=0)
    print(f"| **mean** | | **{m[0]:.2f} / {m[1]:.2f} / {m[2]:.2f}** | **{v[0]:.2f} / {v[1]:.2f} / {v[2]:.2f}** | "
          f"{m[0] / v[0]:.2f} |")
    RESULTS.parent.mkdir(exist_ok=True)
    with RESULTS.open("w", newline="") as f:
        out = csv.writer(f)
        out.writerow(("kind", "trial", "setting") + COLUMNS)
        out.writerows(rows)
    print(f"written: {RESULTS}")


if __name__ == "__main__":
    main()
