"""Where am I on the map? Each lidar scan matched against the map's walls by point-to-plane ICP.

The map's walls are sampled as points with their exact normals (:func:`wall_points`); a scan (in
the sensor's frame) aligned onto them gives the sensor's pose in the map, ``(x, y, yaw)``, and the
information of that pose (:class:`~quadlib.perception.icp.IcpResult`, reordered). Tracking a flight
(:func:`track_scans`), each scan starts from the pose the previous two predict at constant
velocity, so ICP starts well inside its basin (the benchmark ``icp_basin.py`` measures it); the
tracker never sees the navigation filter, so its errors and the filter's stay independent (a
loosely coupled design).

The map's frame is the navigation frame's horizontal plane: x north, y east, and the yaw a turn
from x towards y (the lidar's counter-clockwise bearings, seen from above with z down).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.geometry.rotations import wrap_angle
from quadlib.perception.icp import icp
from quadlib.validation import as_count, as_finite_array, as_positive, as_probability, as_vector

__all__ = ["MapMatch", "scan_to_map", "track_scans", "wall_points"]


def wall_points(segments, spacing_m: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    """Points (M, 2) every ``spacing_m`` along each wall segment of ``segments`` (S, 2, 2), with each
    wall's unit normal (M, 2)."""
    seg = as_finite_array("segments", segments)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise ValueError(f"segments: expected wall segments of shape (S, 2, 2), got {seg.shape}")
    spacing = as_positive("spacing_m", spacing_m)
    points, normals = [], []
    for a, b in seg:
        length = float(np.linalg.norm(b - a))
        if length == 0.0:
            continue
        n = max(2, int(np.ceil(length / spacing)) + 1)
        s = np.linspace(0.0, 1.0, n)[:, None]
        points.append(a + s * (b - a))
        normals.append(np.tile([-(b - a)[1], (b - a)[0]] / np.float64(length), (n, 1)))
    return np.vstack(points), np.vstack(normals)


@dataclass(frozen=True)
class MapMatch:
    """One scan matched to the map: the sensor's ``pose`` ``(x, y, yaw)`` [m, m, rad], its
    ``information`` (3, 3) over the same, ``rmse`` of the matched points [m], ICP's ``iterations``
    and whether it ``converged``."""

    pose: np.ndarray
    information: np.ndarray
    rmse: float
    iterations: int
    converged: bool


def scan_to_map(points, map_points, map_normals, initial_pose, *, trim: float = 0.1,
                max_iterations: int = 30) -> MapMatch:
    """Match scan ``points`` (K, 2) (sensor frame) to the map's ``map_points`` and ``map_normals``
    (M, 2) (:func:`wall_points`), starting at ``initial_pose`` ``(x, y, yaw)``; ``trim`` drops that
    share of the worst pairs (a person, a door the map lacks)."""
    x, y, yaw = as_vector("initial_pose", initial_pose, 3)
    points = _planar("points", points)
    map_points, map_normals = _planar("map_points", map_points), _planar("map_normals", map_normals)
    if map_normals.shape != map_points.shape:
        raise ValueError(f"map_normals: expected one per map point, shape {map_points.shape}, got {map_normals.shape}")
    if trim != 0.0:
        trim = as_probability("trim", trim)
    c, s = np.cos(yaw), np.sin(yaw)
    result = icp(points, map_points, method="plane", target_normals=map_normals, trim=trim,
                 max_iterations=max_iterations, initial=(np.array([[c, -s], [s, c]]), np.array([x, y])))
    order = [1, 2, 0]  # (rotation, tx, ty) → (x, y, yaw)
    pose = np.array([result.t[0], result.t[1], np.arctan2(result.R[1, 0], result.R[0, 0])])
    return MapMatch(pose=pose, information=result.information[np.ix_(order, order)], rmse=result.rmse,
                    iterations=result.iterations, converged=result.converged)


def track_scans(scans, map_points, map_normals, initial_pose, *, trim: float = 0.1,
                min_points: int = 10) -> list[MapMatch | None]:
    """Match each scan of ``scans`` (a sequence of (K, 2) point arrays) in turn, each from the
    constant-velocity prediction of the previous two matches (the first from ``initial_pose``).
    A scan with fewer than ``min_points`` returns gives ``None`` (no fix) and the next one starts
    from the last match."""
    pose = as_vector("initial_pose", initial_pose, 3)
    min_points = as_count("min_points", min_points, low=3)
    out, previous, last = [], None, pose
    for j, pts in enumerate(scans):
        pts = as_finite_array(f"scans[{j}]", pts, ndim=2)
        if pts.shape[1] != 2:
            raise ValueError(f"scans[{j}]: expected points (x, y) of shape (n, 2), got {pts.shape}")
        if pts.shape[0] < min_points:
            out.append(None)
            previous = None
            continue
        guess = last if previous is None else last + _pose_difference(last, previous)
        match = scan_to_map(pts, map_points, map_normals, guess, trim=trim)
        out.append(match)
        previous, last = last, match.pose
    return out


def _planar(name: str, value) -> np.ndarray:
    pts = as_finite_array(name, value, ndim=2)
    if pts.shape[1] != 2 or pts.shape[0] < 3:
        raise ValueError(f"{name}: expected at least 3 points (x, y), shape (n, 2), got {pts.shape}")
    return pts


def _pose_difference(a, b):
    d = a - b
    d[2] = wrap_angle(d[2])
    return d
