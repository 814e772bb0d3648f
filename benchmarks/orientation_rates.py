"""The orientation filter away from the rate it was tuned at: BROAD at lower rates, the fixed-wing flight at three.

Usage: ``python benchmarks/orientation_rates.py`` (about 10 s on 2 cores). :class:`OrientationParams`'
defaults were chosen on BROAD's ten trials, all sampled at 286 Hz, and its noise settings are per
sample. An engineer's IMU runs at another rate, so this measures, with the defaults and no
re-tuning:

* BROAD's ten trials at their own rate and thinned to every second and third sample (143 and
  95 Hz): the gyro averaged over each block of samples (``gyro[k]`` holds over ``[t[k], t[k+1])``,
  so the block's mean is the rate over the longer interval), the accelerometer, magnetometer and
  truth taken at the block's first sample. Printed per rate: the mean total / heading / inclination
  error [deg] of the MEKF and of VQF, and the worst trial's total against VQF's;
* chapter 15's fixed-wing flight without airspeed (:func:`~quadlib.fixedwing.fixedwing_flight`) at
  25, 50 and 100 Hz, ten noise draws each: the MEKF's and VQF's mean total error, the MEKF's worst
  draw, and on how many draws the MEKF is the worse of the two.
"""

from __future__ import annotations

from multiprocessing import Pool

import numpy as np

from quadlib.analysis.metrics import broad_errors
from quadlib.analysis.orientation_table import orientation_estimate
from quadlib.attitude import estimate_orientation
from quadlib.data import broad_trial_names, load_broad_trial
from quadlib.fixedwing import FixedWingNoise, fixedwing_flight, fixedwing_samples
from quadlib.imu import ImuLog

THINNING = (1, 2, 3)
FLIGHT_RATES_HZ = (25.0, 50.0, 100.0)
FLIGHT_SEEDS = range(10, 20)
COLUMNS = ("total_deg", "heading_deg", "inclination_deg")


def thinned(log: ImuLog, q_truth: np.ndarray, movement: np.ndarray, every: int):
    """``log``, its truth and its movement mask at every ``every``-th sample (the gyro averaged over each block)."""
    n = len(log) // every * every
    gyro = log.gyro[:n].reshape(-1, every, 3).mean(axis=1)
    return (ImuLog(log.t[:n:every], gyro, log.accel[:n:every], log.mag[:n:every]), q_truth[:n:every],
            movement[:n:every])


def errors(log: ImuLog, q_truth, movement=None, declination_rad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """BROAD's three errors [deg] of the MEKF and of VQF over ``log``."""
    mekf = broad_errors(estimate_orientation(log, declination_rad=declination_rad).q, q_truth, movement)
    vqf = broad_errors(orientation_estimate("VQF", log), q_truth, movement)
    return np.array([mekf[c] for c in COLUMNS]), np.array([vqf[c] for c in COLUMNS])


def one_trial(job):
    name, every = job
    trial = load_broad_trial(name)
    return every, errors(*thinned(trial.log, trial.q_nb, trial.movement, every))


def one_flight(job):
    rate_hz, seed = job
    flight, noise = fixedwing_flight(rate_hz=rate_hz), FixedWingNoise()
    log = fixedwing_samples(flight, noise, np.random.default_rng(seed))
    return rate_hz, errors(log, flight.q_nb, declination_rad=noise.declination_rad)


def main() -> None:
    with Pool(2) as pool:
        trials = pool.map(one_trial, [(n, e) for e in THINNING for n in broad_trial_names()], chunksize=1)
        flights = pool.map(one_flight, [(r, s) for r in FLIGHT_RATES_HZ for s in FLIGHT_SEEDS], chunksize=1)
    print("BROAD's trials thinned (defaults tuned at 286 Hz); total / heading / inclination [deg], mean over trials")
    print(f"{'rate':<8} | {'MEKF':>18} | {'VQF':>18} | {'worst trial, MEKF / VQF':>23}")
    for every in THINNING:
        mekf, vqf = (np.array([r[1][i] for r in trials if r[0] == every]) for i in (0, 1))
        m, v = mekf.mean(axis=0), vqf.mean(axis=0)
        print(f"{286 / every:4.0f} Hz  | {m[0]:5.2f} / {m[1]:4.2f} / {m[2]:4.2f} | {v[0]:5.2f} / {v[1]:4.2f} / "
              f"{v[2]:4.2f} | {np.max(mekf[:, 0] / vqf[:, 0]):23.2f}")
    print()
    print("Chapter 15's fixed-wing flight without airspeed, ten noise draws per rate; total error [deg]")
    print(f"{'rate':<8} | {'MEKF mean':>9} | {'MEKF worst':>10} | {'VQF mean':>8} | {'MEKF / VQF':>10} | "
          f"{'draws MEKF worse':>16}")
    for rate in FLIGHT_RATES_HZ:
        mekf, vqf = (np.array([r[1][i][0] for r in flights if r[0] == rate]) for i in (0, 1))
        print(f"{rate:4.0f} Hz  | {mekf.mean():9.2f} | {mekf.max():10.2f} | {vqf.mean():8.2f} | "
              f"{mekf.mean() / vqf.mean():10.2f} | {int(np.sum(mekf > vqf)):>13} / {len(mekf)}")


if __name__ == "__main__":
    main()
