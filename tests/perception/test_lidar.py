"""The 2D lidar: ranges against geometry, dropouts and range limits, and scan-to-scan ICP on it."""

import numpy as np
import pytest

from quadlib.perception import corridor_map, icp, lidar_scan, room_map


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
