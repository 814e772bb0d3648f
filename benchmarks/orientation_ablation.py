"""What each idea of the orientation filter buys: its defaults with one setting switched off at a time.

Usage: ``python benchmarks/orientation_ablation.py`` (about 3 minutes on 2 cores). On BROAD's ten
trials, :func:`quadlib.estimate_orientation` online with the defaults, then with each of the
settings below set to None (``tilt_aware_heading`` to False), the rest at their defaults. Printed
per setting: the mean over the trials of BROAD's total, heading and inclination RMSE [deg]
(:func:`quadlib.analysis.broad_errors`), the worst trial's total, and the cost per sample [µs] on
all trials together, with its ratio to the defaults' measured in this run.
"""

from __future__ import annotations

import time
from dataclasses import replace
from multiprocessing import Pool

import numpy as np

from quadlib.analysis.metrics import broad_errors
from quadlib.attitude import OrientationParams, estimate_orientation
from quadlib.data import broad_trial_names, load_broad_trial

SWITCHED_OFF = ("accel_tau_s", "rest_min_s", "tilt_refinement_deg", "tilt_aware_heading", "gate_probability",
                "heading_reset_s", "gravity_reset_s", "mag_settle_s", "mag_reference_tau_s", "mag_new_field_s",
                "mag_first_field_s")


def settings() -> dict[str, OrientationParams]:
    """The defaults, then each setting of :data:`SWITCHED_OFF` switched off alone."""
    off = {name: replace(OrientationParams(), **{name: False if name == "tilt_aware_heading" else None})
           for name in SWITCHED_OFF}
    return {"defaults": OrientationParams(), **{f"{name}={getattr(p, name)}": p for name, p in off.items()}}


def score(trial: str) -> dict[str, tuple[dict[str, float], float, int]]:
    """Each setting's errors on ``trial``, the seconds its estimate took (best of two) and the samples."""
    data = load_broad_trial(trial)
    out = {}
    for label, params in settings().items():
        seconds = []
        for _ in range(2):
            start = time.perf_counter()
            q = estimate_orientation(data.log, params=params).q
            seconds.append(time.perf_counter() - start)
        out[label] = broad_errors(q, data.q_nb, data.movement), min(seconds), len(data.log)
    return out


def main() -> None:
    estimate_orientation(load_broad_trial(broad_trial_names()[0]).log)  # load the compiled loops once
    with Pool(2) as pool:
        trials = pool.map(score, broad_trial_names())
    print(f"estimate_orientation online on {len(trials)} BROAD trials; errors [deg], means over the trials")
    print(f"{'setting':<28} | {'total':>6} | {'heading':>7} | {'incl.':>6} | {'worst':>6} | {'µs/sample':>9} | "
          f"{'× defaults':>10}")
    cost = {label: 1e6 * sum(trial[label][1] for trial in trials) / sum(trial[label][2] for trial in trials)
            for label in settings()}
    for label, us in cost.items():
        errors = [trial[label][0] for trial in trials]
        mean = {k: np.mean([e[k] for e in errors]) for k in errors[0]}
        print(f"{label:<28} | {mean['total_deg']:6.2f} | {mean['heading_deg']:7.2f} | {mean['inclination_deg']:6.2f} | "
              f"{max(e['total_deg'] for e in errors):6.2f} | {us:9.2f} | {us / cost['defaults']:10.2f}")


if __name__ == "__main__":
    main()
