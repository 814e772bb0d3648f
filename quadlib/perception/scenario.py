"""A localisation problem with an ambiguous start: a robot in a corner of a rectangular room.

The room is :func:`~quadlib.perception.lidar.room_map` (20 m × 12 m, two pillars) with one low
cupboard against the south wall. The lidar reaches 4 m, so from the start — 1.5 m from the south
and west walls, facing east — it sees two walls meeting at a right angle, which it would see
the same from the matching pose in any of the four corners (:attr:`LocalisationScenario.hypotheses`).
The robot drives east along the south wall; the east and north corners' hypotheses meet a wall
ahead that the truth does not, and the cupboard, which the room's 180° symmetry does not repeat,
rules out the diagonal corner.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from quadlib.perception.lidar import lidar_scan, room_map
from quadlib.perception.particles import _poses, localise, pose_error
from quadlib.validation import as_count, as_positive, as_rng, as_vector

__all__ = ["LocalisationScenario", "corner_start", "corner_trials", "hypothesis_particles"]

WIDTH_M, DEPTH_M, MAX_RANGE_M = 20.0, 12.0, 4.0
CUPBOARD = (9.0, 0.0, 10.5, 0.6)


@dataclass(frozen=True)
class LocalisationScenario:
    """The map ``walls`` (S, 2, 2); the ``truth`` poses (K, 3) at the scans, every ``dt`` [s]; the
    measured ``odometry`` (K, 2) ``(v, ω)`` leading to each; the scans' ``bearings`` (B,) and
    ``ranges`` (K, B) (NaN: no return) up to ``max_range_m``; and the four ``hypotheses`` (4, 3)
    for the start, the truth first."""

    walls: np.ndarray
    dt: float
    truth: np.ndarray
    odometry: np.ndarray
    bearings: np.ndarray
    ranges: np.ndarray
    max_range_m: float
    hypotheses: np.ndarray


def corner_start(rng, *, beams: int = 12, speed_m_s: float = 0.6, duration_s: float = 24.0, dt: float = 0.2,
                 odometry_sigma=(0.03, 0.01), range_sigma_m: float = 0.02,
                 dropout: float = 0.05) -> LocalisationScenario:
    """Simulate the drive (module documentation): ``duration_s`` at ``speed_m_s`` east, a scan of
    ``beams`` beams (σ ``range_sigma_m``, a share ``dropout`` lost) every ``dt``, odometry with
    white noise ``odometry_sigma = (σ_v, σ_ω)``."""
    rng = as_rng(rng)
    speed, duration, dt = (as_positive(n, v) for n, v in (("speed_m_s", speed_m_s), ("duration_s", duration_s),
                                                           ("dt", dt)))
    k = int(round(duration / dt))
    if not 1 <= k <= int((WIDTH_M - 3.0) / (speed * dt)):
        raise ValueError(f"duration_s: expected a drive that stays in the room, at most {WIDTH_M - 3.0:.1f} m "
                         f"({(WIDTH_M - 3.0) / speed:.1f} s at {speed} m/s), got {duration_s!r} s")
    sigma = as_vector("odometry_sigma", odometry_sigma, 2)
    if np.any(sigma < 0):
        raise ValueError(f"odometry_sigma: expected (σ_v, σ_ω) >= 0, got {sigma.tolist()}")
    walls = room_map(WIDTH_M, DEPTH_M, pillars=2, boxes=[CUPBOARD])
    truth = np.column_stack([1.5 + speed * dt * np.arange(1, k + 1), np.full(k, 1.5), np.zeros(k)])
    scans = [lidar_scan(pose, walls, rng, beams=beams, max_range_m=MAX_RANGE_M, range_sigma_m=range_sigma_m,
                        dropout=dropout) for pose in truth]
    odometry = np.column_stack([speed + sigma[0] * rng.standard_normal(k), sigma[1] * rng.standard_normal(k)])
    hypotheses = np.array([[1.5, 1.5, 0.0], [WIDTH_M - 1.5, 1.5, np.pi / 2], [WIDTH_M - 1.5, DEPTH_M - 1.5, np.pi],
                           [1.5, DEPTH_M - 1.5, -np.pi / 2]])
    return LocalisationScenario(walls=walls, dt=dt, truth=truth, odometry=odometry, bearings=scans[0].bearings,
                                ranges=np.array([s.ranges for s in scans]), max_range_m=MAX_RANGE_M,
                                hypotheses=hypotheses)


def hypothesis_particles(hypotheses, n: int, rng, sigma=(0.3, 0.3, 0.087)) -> np.ndarray:
    """``n`` particles (n, 3) shared equally at random among the ``hypotheses`` (H, 3), each spread
    by Gaussian noise of σ ``sigma = (σ_x, σ_y, σ_yaw)`` [m, m, rad] (default 0.3 m and 5°): the
    belief "in one of these poses"."""
    hyp = _poses("hypotheses", hypotheses)
    n = as_count("n", n)
    s = as_vector("sigma", sigma, 3)
    if np.any(s < 0):
        raise ValueError(f"sigma: expected (σ_x, σ_y, σ_yaw) >= 0, got {s.tolist()}")
    rng = as_rng(rng)
    return hyp[rng.integers(hyp.shape[0], size=int(n))] + rng.standard_normal((int(n), 3)) * s


def corner_trials(particles: int, runs: int, *, scheme: str = "systematic", sigma_m: float = 0.5,
                  first_seed: int = 0) -> tuple[float, float, float]:
    """Run the particle filter from the four corner hypotheses on ``runs`` simulated drives (seeds
    ``first_seed, first_seed + 1, …``): the share that end within 0.5 m and 10° of the truth, their
    median position error [m] (NaN if none), and the filter's mean time per run [s] (the
    simulation excluded; a ratio between settings, not a benchmark of the machine)."""
    particles, runs = as_count("particles", particles), as_count("runs", runs)
    found, errors, seconds = 0, [], 0.0
    for seed in range(first_seed, first_seed + runs):
        rng = np.random.default_rng(seed)
        sc = corner_start(rng)
        start = time.perf_counter()
        run = localise(hypothesis_particles(sc.hypotheses, particles, rng), sc.odometry, sc.ranges, sc.bearings,
                       sc.walls, sc.dt, rng, max_range_m=sc.max_range_m, sigma_m=sigma_m, scheme=scheme)
        seconds += time.perf_counter() - start
        d, a = pose_error(run.pose[-1], sc.truth[-1])
        if d < 0.5 and a < np.radians(10.0):
            found += 1
            errors.append(d)
    return found / runs, float(np.median(errors)) if errors else float("nan"), seconds / runs
