"""The 2D lidar: ranges against geometry, dropouts and range limits, and scan-to-scan ICP on it."""

import numpy as np
import pytest

from quadlib.perception import cast_rays, corridor_map, icp, lidar_scan, room_map


def test_ranges_are_the_distances_to_the_walls():
    scan = lidar_scan([5.0, 4.0, 0.0], room_map(20.0, 12.0, pillars=0), np.random.default_rng(0), range_sigma_m=0.0,
                      beams=4)  # bearings −180°, −90°, 0°, 90°
    np.testing.assert_allclose(scan.ranges, [5.0, 4.0, 15.0, 8.0], atol=1e-12)
    turned = lidar_scan([5.0, 4.0, np.pi / 2], room_map(20.0, 12.0, pillars=0), np.random.default_rng(0),
                        range_sigma_m=0.0, beams=4)
    np.testing.assert_allclose(turned.ranges, [4.0, 15.0, 8.0, 5.0], atol=1e-12)  # the beams turn with the body
    np.testing.assert_allclose(np.hypot(*turned.points.T), turned.ranges, atol=1e-12)


def test_range_limit_dropouts_and_noise():
    rng = np.random.default_rng(1)
    scan = lidar_scan([1.0, 1.0, 0.0], corridor_map(30.0, 2.0), rng, max_range_m=5.0, dropout=0.2, range_sigma_m=0.02)
    assert np.isnan(scan.ranges).mean() > 0.2  # beams along the corridor see nothing within 5 m
    assert scan.points.shape == (int((~np.isnan(scan.ranges)).sum()), 2)
    clean = lidar_scan([1.0, 1.0, 0.0], corridor_map(30.0, 2.0), rng, range_sigma_m=0.0)
    noisy = lidar_scan([1.0, 1.0, 0.0], corridor_map(30.0, 2.0), rng, range_sigma_m=0.02)
    both = ~np.isnan(clean.ranges) & ~np.isnan(noisy.ranges)
    assert np.std(noisy.ranges[both] - clean.ranges[both]) == pytest.approx(0.02, rel=0.25)


def test_scan_to_scan_icp_recovers_the_motion_in_a_room():
    rng = np.random.default_rng(2)
    first = lidar_scan([5.0, 4.0, 0.0], room_map(), rng)
    second = lidar_scan([5.3, 4.1, np.radians(5.0)], room_map(), rng)
    result = icp(second.points, first.points, method="plane")
    assert np.degrees(np.arctan2(result.R[1, 0], result.R[0, 0])) == pytest.approx(5.0, abs=0.1)
    np.testing.assert_allclose(result.t, [0.3, 0.1], atol=0.02)  # the second pose in the first's frame


def test_bad_maps_and_settings_are_named():
    with pytest.raises(ValueError, match=r"segments: expected wall segments of shape \(S, 2, 2\)"):
        lidar_scan([0.0, 0.0, 0.0], np.zeros((3, 2)), np.random.default_rng(0))
    with pytest.raises(ValueError, match="dropout: expected a fraction in"):
        lidar_scan([0.0, 0.0, 0.0], room_map(), np.random.default_rng(0), dropout=1.0)


def _broadcast_first_hits(origins, headings, bearings, segments):
    """The same intersections as numpy broadcasting over (poses, beams, walls): the reference."""
    d = np.stack([np.cos(headings[:, None] + bearings), np.sin(headings[:, None] + bearings)], axis=-1)
    a, e = segments[:, 0], segments[:, 1] - segments[:, 0]
    rel = a[None, :, :] - origins[:, None, :]
    dx, dy, ex, ey = d[:, :, None, 0], d[:, :, None, 1], e[None, None, :, 0], e[None, None, :, 1]
    rx, ry = rel[:, None, :, 0], rel[:, None, :, 1]
    det = -dx * ey + dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        r, s = (-rx * ey + ry * ex) / det, (dx * ry - dy * rx) / det
    hit = (np.abs(det) > 1e-12) & (r > 0.0) & (s >= 0.0) & (s <= 1.0)
    return np.where(hit, r, np.inf).min(axis=2)


def test_the_compiled_ray_caster_equals_numpy_broadcasting_bit_for_bit():
    rng = np.random.default_rng(4)
    walls = room_map(16.0, 16.0, pillars=2, boxes=[(5.0, 13.0, 7.0, 16.0)])
    origins, headings = rng.uniform(0.5, 15.5, (200, 2)), rng.uniform(-np.pi, np.pi, 200)
    origins[0] = [8.0, 8.0]  # on a pillar's edge line, beams along walls included
    bearings = np.arange(72) * (2.0 * np.pi / 72) - np.pi
    fast = cast_rays(origins, headings, bearings, walls)
    np.testing.assert_array_equal(fast, _broadcast_first_hits(origins, headings, bearings, walls))
    assert np.isfinite(fast).all()  # a closed room: every beam meets a wall
    corridor = cast_rays(np.array([[1.0, 1.0]]), np.zeros(1), np.array([0.0, np.pi / 2]), corridor_map(30.0, 2.0))
    np.testing.assert_array_equal(corridor, [[np.inf, 1.0]])  # along the corridor no wall: inf
