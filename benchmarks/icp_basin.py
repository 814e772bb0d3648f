"""ICP's convergence basin and iteration counts, point-to-point against point-to-plane.

Usage: ``python benchmarks/icp_basin.py`` (under a minute). Two scans of the room of
``quadlib.perception.room_map`` (360 beams, 1 cm noise) are taken from the same place; the second
is turned by an initial rotation error and shifted by an initial translation error, and ICP must
bring it back (:func:`quadlib.perception.convergence_basin`). For each error and variant: the share
of 20 seeded pairs that end within 0.5° and 5 cm of the truth, and their median iteration count.
"""

from __future__ import annotations

import numpy as np

from quadlib.perception import convergence_basin, lidar_scan, room_map

ROTATIONS_DEG = (5, 15, 30, 45, 60, 90, 120, 150)
SHIFTS_M = (0.2, 1.0)


def scan_pairs(n: int = 20) -> list:
    walls, pairs = room_map(), []
    for seed in range(n):
        rng = np.random.default_rng(seed)
        target = lidar_scan([6.0, 4.0, 0.0], walls, rng).points
        pairs.append((lidar_scan([6.0, 4.0, 0.0], walls, rng).points, target))
    return pairs


def main() -> None:
    pairs = scan_pairs()
    results = {m: convergence_basin(pairs, np.radians(ROTATIONS_DEG), SHIFTS_M, m) for m in ("point", "plane")}
    print(f"{'rotation':>8} {'shift':>6} | {'point: ok':>9} {'iters':>5} | {'plane: ok':>9} {'iters':>5}")
    for i, rot in enumerate(ROTATIONS_DEG):
        for j, shift in enumerate(SHIFTS_M):
            cells = [f"{100 * results[m][0][i, j]:8.0f}% {int(results[m][1][i, j]):5d}" for m in ("point", "plane")]
            print(f"{rot:7d}° {shift:5.1f}m | {cells[0]} | {cells[1]}")


if __name__ == "__main__":
    main()
