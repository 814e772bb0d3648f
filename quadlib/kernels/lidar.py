"""The ray caster of :mod:`quadlib.perception.lidar`, compiled: the scan simulator and the particle
filter cast every beam of every pose against every wall."""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.kernels import called_from_python

__all__: list[str] = []  # called by quadlib.perception.lidar


@called_from_python
@njit(cache=True)
def first_hits(origins, directions, segments):
    """For every pose ``n`` and beam ``b``, the nearest wall hit: ``p + r d = a + s e`` solved for
    ``r, s`` by Cramer's rule, a hit where ``r > 0`` and ``0 ≤ s ≤ 1``. A compiled loop: as numpy
    broadcasting over (poses, beams, walls) it made a dozen temporary arrays and cost 4–6 × more."""
    N, B = directions.shape[0], directions.shape[1]
    ranges = np.full((N, B), np.inf)
    for n in range(N):
        for b in range(B):
            dx, dy = directions[n, b, 0], directions[n, b, 1]
            for k in range(segments.shape[0]):
                ax, ay = segments[k, 0, 0], segments[k, 0, 1]
                ex, ey = segments[k, 1, 0] - ax, segments[k, 1, 1] - ay
                rx, ry = ax - origins[n, 0], ay - origins[n, 1]
                det = -dx * ey + dy * ex
                if abs(det) > 1e-12:  # not parallel
                    r = (-rx * ey + ry * ex) / det
                    s = (dx * ry - dy * rx) / det
                    if r > 0.0 and 0.0 <= s <= 1.0 and r < ranges[n, b]:
                        ranges[n, b] = r
    return ranges
