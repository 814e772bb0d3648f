"""Orientation on the six BROAD trials: quadlib's MEKF against VQF and ahrs, in one run.

Usage: ``python benchmarks/broad_orientation.py`` (about 10 minutes on 2 cores). Prints, per trial
and as the mean over the trials, BROAD's total / heading / inclination RMSE [deg] (Laidig et al.
2021; :func:`quadlib.analysis.broad_errors`) and the cost per sample [µs] of each estimator, all
with default parameters (no per-trial tuning).

Frames: quadlib works in NED. VQF and ahrs Mahony return sensor-to-ENU quaternions, ahrs Madgwick
sensor-to-NWU (x north, z up); each is turned into NED with the fixed rotation between the frames
(the same ENU→NED rotation the loader applies to the optical truth). The check that the frames
are right: VQF reproduces its published means on these trials (2.74° / 2.64° / 0.56°, offline
1.75°). ahrs's EKF is left out: no frame and sign convention made its output match the truth on a
slow trial.
"""

from __future__ import annotations

import time
from multiprocessing import Pool

import numpy as np
from ahrs.filters import Madgwick, Mahony
from vqf import VQF, BasicVQF, offlineVQF

from quadlib.analysis.metrics import broad_errors
from quadlib.attitude import estimate_orientation
from quadlib.data import broad_trial_names, load_broad_trial
from quadlib.geometry.quaternion import quat_multiply

ENU_TO_NED = np.array([0.0, np.sqrt(0.5), np.sqrt(0.5), 0.0])
NWU_TO_NED = np.array([0.0, 1.0, 0.0, 0.0])


def _estimators(log):
    Ts = float(np.median(log.dt))
    gyr, acc, mag = (np.ascontiguousarray(a, dtype=float) for a in (log.gyro, log.accel, log.mag))
    return {
        "quadlib MEKF": lambda: estimate_orientation(log),
        "VQF": lambda: quat_multiply(ENU_TO_NED, VQF(Ts).updateBatch(gyr, acc, mag)["quat9D"]),
        "BasicVQF": lambda: quat_multiply(ENU_TO_NED, BasicVQF(Ts).updateBatch(gyr, acc, mag)["quat9D"]),
        "offline VQF": lambda: quat_multiply(ENU_TO_NED, offlineVQF(gyr, acc, mag, Ts)["quat9D"]),
        "ahrs Madgwick": lambda: quat_multiply(NWU_TO_NED, Madgwick(gyr=gyr, acc=acc, mag=mag, frequency=1 / Ts).Q),
        "ahrs Mahony": lambda: quat_multiply(ENU_TO_NED, Mahony(gyr=gyr, acc=acc, mag=mag, frequency=1 / Ts).Q),
    }


def one_trial(name):
    trial = load_broad_trial(name)
    rows = {}
    for label, estimate in _estimators(trial.log).items():
        start = time.perf_counter()
        q = estimate()
        cost = (time.perf_counter() - start) / len(trial.log) * 1e6
        e = broad_errors(q, trial.q_nb, trial.movement)
        rows[label] = (e["total_deg"], e["heading_deg"], e["inclination_deg"], cost)
    return name, rows


def main() -> None:
    with Pool(2) as pool:
        results = dict(pool.map(one_trial, broad_trial_names()))
    labels = list(next(iter(results.values())))
    print("total / heading / inclination RMSE [deg], cost [µs per sample]")
    print("| trial | " + " | ".join(labels) + " |")
    print("|---|" + "---|" * len(labels))
    for name, rows in results.items():
        print(f"| {name} | " + " | ".join("{:.2f} / {:.2f} / {:.2f}".format(*rows[k][:3]) for k in labels) + " |")
    means = {k: np.mean([rows[k] for rows in results.values()], axis=0) for k in labels}
    print("| **mean** | " + " | ".join("**{:.2f} / {:.2f} / {:.2f}**".format(*means[k][:3]) for k in labels) + " |")
    print("| µs per sample | " + " | ".join(f"{means[k][3]:.1f}" for k in labels) + " |")


if __name__ == "__main__":
    main()
