"""ICP: exact on noise-free data in 2D and 3D, the reflection guard, point-to-plane's speed, outliers
trimmed, and the corridor's degeneracy in the covariance."""

import numpy as np
import pytest

from quadlib.geometry import quat_from_rotvec, quat_to_dcm
from quadlib.perception import best_rigid_transform, estimate_normals, icp

RNG = np.random.default_rng(0)
S = np.linspace(0.0, 1.0, 100)
ROOM = np.vstack([np.column_stack([10 * S, 0 * S]), np.column_stack([10 * S, 0 * S + 6]),
                  np.column_stack([0 * S, 6 * S]), np.column_stack([0 * S + 10, 6 * S])])


def _turn(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def test_the_svd_step_is_exact_and_never_a_reflection():
    P = RNG.uniform(-5, 5, (50, 3))
    R, t = quat_to_dcm(quat_from_rotvec([0.2, -0.1, 0.3])), np.array([0.5, -0.3, 0.2])
    R_hat, t_hat = best_rigid_transform(P, P @ R.T + t)
    assert np.abs(R_hat - R).max() < 1e-12 and np.abs(t_hat - t).max() < 1e-12
    mirrored = P * [1.0, 1.0, -1.0]  # no rotation does this; the unguarded V Uᵀ answers with the mirror
    U, _, Vt = np.linalg.svd((P - P.mean(0)).T @ (mirrored - mirrored.mean(0)))
    assert np.linalg.det(Vt.T @ U.T) == pytest.approx(-1.0)
    R_hat, _ = best_rigid_transform(P, mirrored)
    assert np.linalg.det(R_hat) == pytest.approx(1.0)


def test_icp_recovers_a_known_transform_in_3d():
    P = RNG.uniform(-5, 5, (300, 3))
    R, t = quat_to_dcm(quat_from_rotvec([0.2, -0.1, 0.3])), np.array([0.5, -0.3, 0.2])
    result = icp(P, P @ R.T + t)
    assert result.converged and np.abs(result.R - R).max() < 1e-9 and np.abs(result.t - t).max() < 1e-9


def test_point_to_plane_aligns_a_room_exactly_where_point_to_point_stops_short():
    R, t = _turn(0.1), np.array([0.3, -0.2])
    source = (ROOM - t) @ R  # R source + t = ROOM
    plane = icp(source, ROOM, method="plane")
    assert plane.converged and np.abs(plane.R - R).max() < 1e-9 and np.abs(plane.t - t).max() < 1e-9
    point = icp(source, ROOM, method="point", max_iterations=200)
    # a fixed point of the pairing: each source point held by the nearest target sample, 1° and 10 cm off
    assert point.converged and point.iterations < 50
    assert np.abs(point.R - R).max() > 0.01 and np.abs(point.t - t).max() > 0.05


def test_trimming_ignores_outliers():
    R, t = _turn(0.05), np.array([0.1, 0.2])
    source = np.vstack([(ROOM - t) @ R, RNG.uniform(2, 8, (30, 2))])  # 30 points the target never saw
    trimmed = icp(source, ROOM, method="plane", trim=0.1)
    untrimmed = icp(source, ROOM, method="plane")
    assert np.abs(trimmed.t - t).max() < 1e-6
    assert np.abs(untrimmed.t - t).max() > 10 * np.abs(trimmed.t - t).max()


def test_a_corridor_leaves_its_length_unknown():
    corridor = np.vstack([np.column_stack([30 * S, 0 * S]), np.column_stack([30 * S, 0 * S + 2])])
    noisy = corridor + RNG.normal(size=corridor.shape) * 0.01
    result = icp(noisy + [0.0, 0.05], corridor, method="plane", target_normals=estimate_normals(corridor))
    along, across = result.covariance[1, 1], result.covariance[2, 2]
    assert along > 10 * across


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="method: expected 'point' or 'plane'"):
        icp(ROOM, ROOM, method="normal")
    with pytest.raises(ValueError, match=r"target: expected points of dimension 2"):
        icp(ROOM, np.zeros((10, 3)))
    with pytest.raises(ValueError, match="source: expected at least d points"):
        icp(np.zeros((5, 4)), ROOM)


def test_the_covariance_matches_the_scatter_of_noisy_matches():
    """Scan-to-map: the sensor sits 6 m from the map's origin, where a rotation about the map's
    origin and one about the sensor differ; the reported σ must match the spread of 200 matches."""
    from quadlib.perception import lidar_scan, room_map, scan_to_map, wall_points

    walls = room_map(20.0, 12.0, pillars=2)
    points, normals = wall_points(walls, 0.05)
    truth = np.array([6.0, 4.0, 0.3])
    rng = np.random.default_rng(5)
    poses, sigmas = [], []
    for _ in range(200):
        scan = lidar_scan(truth, walls, rng, beams=90, range_sigma_m=0.05)
        match = scan_to_map(scan.points, points, normals, truth, trim=0.0)
        poses.append(match.pose)
        sigmas.append(np.sqrt(np.diag(np.linalg.inv(match.information))))
    spread, reported = np.std(poses, axis=0), np.mean(sigmas, axis=0)
    np.testing.assert_allclose(spread[:2], reported[:2], rtol=0.12)  # about the map's origin: 20–70 % too large
    # one σ for every residual: grazing beams, with the longest lever arms, are better than it along their
    # normal (σ cos incidence), so the reported yaw σ is somewhat pessimistic
    assert spread[2] < reported[2] < 1.35 * spread[2]
    assert np.all(np.abs(np.mean(poses, axis=0) - truth) < 4 * spread / np.sqrt(200))  # unbiased


def test_the_convergence_basin_counts_the_pairs_that_return():
    from quadlib.perception import convergence_basin, lidar_scan, room_map

    rng = np.random.default_rng(0)
    pairs = [(lidar_scan([6.0, 4.0, 0.0], room_map(), rng).points, lidar_scan([6.0, 4.0, 0.0], room_map(), rng).points)
             for _ in range(3)]
    found, iterations = convergence_basin(pairs, np.radians([10.0, 180.0]), [0.2], "plane")
    assert found.shape == iterations.shape == (2, 1)
    assert found[0, 0] == 1.0 and found[1, 0] == 0.0  # turned around, the room looks the same: a wrong match
    assert 1 <= iterations[0, 0] < iterations[1, 0] or iterations[1, 0] == 100
    with pytest.raises(ValueError, match="scans: expected at least one"):
        convergence_basin([], [0.1], [0.1], "plane")


def test_the_convergence_measure_sees_turns_far_below_arccos_resolution():
    from quadlib.perception.icp import _rotation_angle

    for angle in (1e-12, 3e-9, 0.3, 3.0):
        R2 = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        R3 = quat_to_dcm(quat_from_rotvec(angle * np.array([0.6, -0.8, 0.0])))
        assert _rotation_angle(R2) == pytest.approx(angle, rel=1e-9)
        assert _rotation_angle(R3) == pytest.approx(angle, rel=1e-9)
