"""ICP's convergence basin and iteration counts, point-to-point against point-to-plane.

Usage: ``python benchmarks/icp_basin.py`` (a few seconds). Two scans of the room of
``quadlib.perception.room_map`` (360 beams, 1 cm noise) are taken from the same place; the second
is turned by an initial rotation error and shifted by an initial translation error, and ICP must
bring it back. For each error and variant: the share of 20 seeded trials that end within 0.5° and
5 cm of the truth, and their median iteration count.
"""

from __future__ import annotations

import numpy as np

from quadlib.perception import icp, lidar_scan, room_map


def main() -> None:
    walls = room_map()
    print(f"{'rotation':>8} {'shift':>6} | {'point: ok':>9} {'iters':>5} | {'plane: ok':>9} {'iters':>5}")
    for rot_deg in (5, 15, 30, 45, 60, 90):
        for shift in (0.2, 1.0):
            cells = []
            for method in ("point", "plane"):
                ok, iters = 0, []
                for seed in range(20):
                    rng = np.random.default_rng(seed)
                    target = lidar_scan([6.0, 4.0, 0.0], walls, rng).points
                    source = lidar_scan([6.0, 4.0, 0.0], walls, rng).points
                    a = np.radians(rot_deg)
                    R0 = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
                    t0 = shift * np.array([np.cos(seed), np.sin(seed)])
                    r = icp(source, target, method=method, initial=(R0, t0), max_iterations=100)
                    angle = np.degrees(abs(np.arctan2(r.R[1, 0], r.R[0, 0])))
                    ok += angle < 0.5 and np.linalg.norm(r.t) < 0.05
                    iters.append(r.iterations)
                cells.append(f"{100 * ok / 20:8.0f}% {int(np.median(iters)):5d}")
            print(f"{rot_deg:7d}° {shift:5.1f}m | {cells[0]} | {cells[1]}")


if __name__ == "__main__":
    main()
