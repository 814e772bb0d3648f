"""A 2D scanning lidar in a map of wall segments: the scans ICP aligns.

Each beam leaves the sensor at its bearing (relative to the body's x axis, counter-clockwise in the
map's x–y plane) and returns the distance to the first wall it meets: for a beam ``p + r d`` and a
wall ``a + s (b − a)``, ``r`` and ``s`` solve a 2 × 2 linear system, and the hit counts when
``r > 0`` and ``0 ≤ s ≤ 1``. Beyond ``max_range_m``, or dropped at random, a beam returns nothing
(NaN). Range noise is white with σ ``range_sigma_m``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.kernels.lidar import first_hits
from quadlib.validation import as_count, as_finite_array, as_positive, as_rng, as_vector

__all__ = ["LidarScan", "cast_rays", "corridor_map", "lidar_scan", "room_map"]


def _box(x0, y0, x1, y1):
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)
    return np.stack([corners, np.roll(corners, -1, axis=0)], axis=1)


def room_map(width_m: float = 20.0, depth_m: float = 12.0, pillars: int = 2, boxes=None) -> np.ndarray:
    """Wall segments ``(S, 2, 2)`` of a rectangular room ``[0, width] × [0, depth]`` with square
    pillars (0.6 m) along its middle and, optionally, ``boxes`` (cupboards, crates): rectangles
    ``(x0, y0, x1, y1)`` [m]. Without boxes the room looks the same turned by 180° about its centre."""
    w, d = as_positive("width_m", width_m), as_positive("depth_m", depth_m)
    pillars = as_count("pillars", pillars, low=0)
    rects = np.zeros((0, 4)) if boxes is None else as_finite_array("boxes", boxes, ndim=2)
    if rects.shape[1] != 4 or np.any(rects[:, 2:] <= rects[:, :2]):
        raise ValueError(f"boxes: expected rectangles (x0, y0, x1, y1) with x1 > x0 and y1 > y0, got {boxes!r}")
    walls = [_box(0.0, 0.0, w, d)]
    for i in range(pillars):
        cx = w * (i + 1) / (pillars + 1)
        walls.append(_box(cx - 0.3, d / 2 - 0.3, cx + 0.3, d / 2 + 0.3))
    walls += [_box(*r) for r in rects]
    return np.concatenate(walls)


def corridor_map(length_m: float = 30.0, width_m: float = 2.0) -> np.ndarray:
    """Two long parallel walls ``(2, 2, 2)``: along the corridor a scan looks the same everywhere."""
    length, width = as_positive("length_m", length_m), as_positive("width_m", width_m)
    return np.array([[[0.0, 0.0], [length, 0.0]], [[0.0, width], [length, width]]])


@dataclass(frozen=True)
class LidarScan:
    """One scan: beam ``bearings`` (B,) [rad], ``ranges`` (B,) [m] (NaN: no return), and the returns
    as ``points`` (K, 2) in the sensor frame."""

    bearings: np.ndarray
    ranges: np.ndarray
    points: np.ndarray


def cast_rays(origins: np.ndarray, headings: np.ndarray, bearings: np.ndarray, segments: np.ndarray) -> np.ndarray:
    """Ranges ``(N, B)`` to the first wall along each bearing from each of ``N`` poses (``inf`` where a
    beam meets none). Unchecked: the scan simulator and the particle filter call it with checked arrays."""
    directions = np.stack([np.cos(headings[:, None] + bearings), np.sin(headings[:, None] + bearings)], axis=-1)
    return first_hits(origins, directions, segments)


def lidar_scan(pose, segments, rng, *, beams: int = 360, max_range_m: float = 20.0, range_sigma_m: float = 0.01,
               dropout: float = 0.0) -> LidarScan:
    """Scan ``segments`` (S, 2, 2) from ``pose = (x, y, yaw)`` [m, m, rad]."""
    x, y, yaw = as_vector("pose", pose, 3)
    seg = as_finite_array("segments", segments)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise ValueError(f"segments: expected wall segments of shape (S, 2, 2), got {seg.shape}")
    beams = as_count("beams", beams)
    max_range = as_positive("max_range_m", max_range_m)
    sigma = as_positive("range_sigma_m", range_sigma_m, allow_zero=True)
    if not (isinstance(dropout, (int, float)) and not isinstance(dropout, bool) and 0.0 <= dropout < 1.0):
        raise ValueError(f"dropout: expected a fraction in [0, 1), got {dropout!r}")
    rng = as_rng(rng)
    bearings = np.arange(beams) * (2.0 * np.pi / beams) - np.pi
    ranges = cast_rays(np.array([[x, y]]), np.array([yaw]), bearings, seg)[0]
    noise = rng.standard_normal(ranges.size) * sigma
    dropped = rng.random(ranges.size) < dropout
    ranges = np.where(np.isfinite(ranges) & (ranges <= max_range) & ~dropped, ranges + noise, np.nan)
    ok = ~np.isnan(ranges)
    points = np.column_stack([ranges[ok] * np.cos(bearings[ok]), ranges[ok] * np.sin(bearings[ok])])
    return LidarScan(bearings=bearings, ranges=ranges, points=points)
