"""The particle filter: resampling schemes, the motion and scan models, and localisation from the
ambiguous corner start."""

import numpy as np
import pytest

from quadlib.perception import (
    RESAMPLING_SCHEMES,
    cast_rays,
    corner_start,
    effective_sample_size,
    hypothesis_particles,
    localise,
    odometry_step,
    particle_pose,
    pose_error,
    resample,
    room_map,
    scan_log_likelihood,
)


def test_effective_sample_size_spans_one_to_n():
    assert effective_sample_size(np.ones(50)) == pytest.approx(50.0)
    assert effective_sample_size(np.r_[1.0, np.zeros(49)]) == pytest.approx(1.0)
    assert effective_sample_size([3.0, 1.0]) == pytest.approx(1.0 / (0.75**2 + 0.25**2))


@pytest.mark.parametrize("scheme", RESAMPLING_SCHEMES)
def test_resampling_draws_in_proportion_to_the_weights(scheme):
    w = np.array([0.5, 0.3, 0.15, 0.05])
    rng = np.random.default_rng(0)
    counts = np.zeros(4)
    for _ in range(400):
        idx = resample(w, rng, scheme)
        assert idx.shape == (40,) or idx.shape == (4,)
        counts += np.bincount(idx, minlength=4)
    np.testing.assert_allclose(counts / counts.sum(), w, atol=0.02)


def test_systematic_keeps_each_particles_share_to_one_copy_and_residual_keeps_its_whole_part():
    w = np.random.default_rng(3).random(200)
    w /= w.sum()
    for seed in range(20):
        systematic = np.bincount(resample(w, np.random.default_rng(seed), "systematic"), minlength=200)
        assert np.all(systematic >= np.floor(200 * w)) and np.all(systematic <= np.ceil(200 * w))
        residual = np.bincount(resample(w, np.random.default_rng(seed), "residual"), minlength=200)
        assert np.all(residual >= np.floor(200 * w)) and residual.sum() == 200


def test_resampling_keeps_a_particle_with_all_the_weight_only():
    for scheme in RESAMPLING_SCHEMES:
        np.testing.assert_array_equal(resample(np.r_[0.0, 1.0, 0.0], np.random.default_rng(0), scheme), [1, 1, 1])


def test_odometry_without_noise_drives_along_the_heading_turned_by_half_the_step():
    p = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, np.pi / 2]])
    out = odometry_step(p, [2.0, 0.0], 0.5, np.random.default_rng(0), (0.0, 0.0))
    np.testing.assert_allclose(out, [[1.0, 0.0, 0.0], [1.0, 3.0, np.pi / 2]], atol=1e-12)
    turn = odometry_step(p[:1], [1.0, 0.4], 1.0, np.random.default_rng(0), (0.0, 0.0))[0]
    np.testing.assert_allclose(turn, [np.cos(0.2), np.sin(0.2), 0.4], atol=1e-12)
    wrapped = odometry_step([[0.0, 0.0, 3.1]], [0.0, 1.0], 0.1, np.random.default_rng(0), (0.0, 0.0))[0, 2]
    assert wrapped == pytest.approx(3.2 - 2 * np.pi)


def test_odometry_noise_spreads_the_particles_by_its_sigma():
    out = odometry_step(np.zeros((20000, 3)), [1.0, 0.0], 1.0, np.random.default_rng(1), (0.1, 0.05))
    assert np.std(out[:, 2]) == pytest.approx(0.05, rel=0.05)
    assert np.std(np.hypot(out[:, 0], out[:, 1])) == pytest.approx(0.1, rel=0.05)


def test_scan_likelihood_peaks_at_the_pose_that_took_the_scan():
    walls = room_map(20.0, 12.0, pillars=2)
    bearings = np.linspace(-np.pi, np.pi, 24, endpoint=False)
    truth = np.array([5.0, 4.0, 0.3])
    ranges = cast_rays(truth[None, :2], truth[2:], bearings, walls)[0]
    ranges = np.where(ranges <= 6.0, ranges, np.nan)
    offsets = np.array([[0, 0, 0], [0.2, 0, 0], [0, -0.2, 0], [0, 0, 0.05], [0.5, 0.5, 0.1]])
    ll = scan_log_likelihood(truth + offsets, bearings, ranges, walls, max_range_m=6.0, sigma_m=0.3)
    assert np.argmax(ll) == 0 and np.all(ll[1:] < ll[0])
    one = scan_log_likelihood(truth[None], bearings, ranges, walls, max_range_m=6.0, sigma_m=0.3, outlier=0.05)[0]
    assert one == pytest.approx(24 * np.log(0.95 / (np.sqrt(2 * np.pi) * 0.3) + 0.05 / 6.0))


def test_a_wrong_beam_costs_a_bounded_amount():
    walls = room_map(20.0, 12.0, pillars=0)
    bearings = np.array([0.0, np.pi / 2])
    ll_ok = scan_log_likelihood([[5.0, 4.0, 0.0]], bearings, [15.0, 8.0], walls, max_range_m=20.0, sigma_m=0.2)
    ll_bad = scan_log_likelihood([[5.0, 4.0, 0.0]], bearings, [1.0, 8.0], walls, max_range_m=20.0, sigma_m=0.2)
    assert np.isfinite(ll_bad[0]) and ll_ok[0] - ll_bad[0] == pytest.approx(
        np.log((0.95 / (np.sqrt(2 * np.pi) * 0.2) + 0.05 / 20.0) / (0.05 / 20.0)), rel=1e-9)


def test_the_particle_pose_averages_headings_as_directions():
    p = np.array([[0.0, 0.0, np.pi - 0.1], [2.0, 0.0, -np.pi + 0.1]])
    mean = particle_pose(p, [1.0, 1.0])
    assert mean[:2] == pytest.approx([1.0, 0.0]) and abs(abs(mean[2]) - np.pi) < 1e-12
    np.testing.assert_allclose(pose_error([1.0, 0.0, np.pi], [0.0, 0.0, -np.pi + 0.2]), [1.0, 0.2], atol=1e-12)


def test_the_corner_start_is_ambiguous_until_the_robot_moves():
    sc = corner_start(np.random.default_rng(0), range_sigma_m=0.0, dropout=0.0)
    start = np.vstack([sc.hypotheses[0], sc.hypotheses[1:]])
    expected = np.minimum(cast_rays(start[:, :2], start[:, 2], sc.bearings, sc.walls), sc.max_range_m)
    np.testing.assert_allclose(expected[1:], np.broadcast_to(expected[0], (3, sc.bearings.size)), atol=1e-9)
    np.testing.assert_allclose(sc.truth[0, :2], sc.hypotheses[0, :2] + [0.6 * sc.dt, 0.0])


def test_localise_picks_the_right_corner():
    found = 0
    for seed in range(10):
        rng = np.random.default_rng(seed)
        sc = corner_start(rng)
        run = localise(hypothesis_particles(sc.hypotheses, 300, rng), sc.odometry, sc.ranges, sc.bearings, sc.walls,
                       sc.dt, rng, max_range_m=sc.max_range_m)
        d, a = pose_error(run.pose[-1], sc.truth[-1])
        found += d < 0.5 and a < np.radians(10.0)
        assert run.ess.shape == (sc.truth.shape[0],) and run.resampled.any()
    assert found >= 9


def test_the_first_scan_leaves_each_corner_about_a_quarter_of_the_weight():
    rng = np.random.default_rng(0)
    sc = corner_start(rng)
    start = hypothesis_particles(sc.hypotheses, 4000, rng)
    corner = np.argmin(np.linalg.norm(start[:, None, :2] - sc.hypotheses[None, :, :2], axis=2), axis=1)
    first = localise(start, sc.odometry[:1], sc.ranges[:1], sc.bearings, sc.walls, sc.dt, rng, max_range_m=4.0,
                     resample_below=0.0)  # no resampling: the particles keep their order
    mass = np.bincount(corner, weights=first.weights, minlength=4)
    np.testing.assert_allclose(mass, 0.25, atol=0.08)


def test_a_single_hypothesis_in_the_wrong_corner_stays_wrong():
    rng = np.random.default_rng(0)
    sc = corner_start(rng)
    run = localise(hypothesis_particles(sc.hypotheses[2:3], 300, rng), sc.odometry, sc.ranges, sc.bearings, sc.walls,
                   sc.dt, rng, max_range_m=sc.max_range_m)
    assert pose_error(run.pose[-1], sc.truth[-1])[0] > 5.0  # no particle near the truth: nothing to find it with


def test_localise_rejects_mismatched_inputs():
    rng = np.random.default_rng(0)
    sc = corner_start(rng, duration_s=2.0)
    p = hypothesis_particles(sc.hypotheses, 20, rng)
    with pytest.raises(ValueError, match="scans: expected one scan of ranges per odometry step"):
        localise(p, sc.odometry, sc.ranges[:-1], sc.bearings, sc.walls, sc.dt, rng, max_range_m=4.0)
    with pytest.raises(ValueError, match="odometry: expected"):
        localise(p, sc.odometry[:, :1], sc.ranges, sc.bearings, sc.walls, sc.dt, rng, max_range_m=4.0)
    with pytest.raises(ValueError, match="scheme: expected one of"):
        localise(p, sc.odometry, sc.ranges, sc.bearings, sc.walls, sc.dt, rng, max_range_m=4.0, scheme="best")
    with pytest.raises(ValueError, match="duration_s: expected a drive that stays in the room"):
        corner_start(rng, duration_s=60.0)


def test_snapshots_keep_the_particles_after_the_steps_asked_for():
    rng = np.random.default_rng(0)
    sc = corner_start(rng, duration_s=2.0)
    run = localise(hypothesis_particles(sc.hypotheses, 50, rng), sc.odometry, sc.ranges, sc.bearings, sc.walls,
                   sc.dt, rng, max_range_m=4.0, snapshots=(0, 9))
    assert set(run.snapshots) == {0, 9}
    particles, weights = run.snapshots[9]
    assert particles.shape == (50, 3) and weights.sum() == pytest.approx(1.0)
    np.testing.assert_allclose(particle_pose(particles, weights), run.pose[9])
    with pytest.raises(ValueError, match=r"snapshots\[0\]: expected an int in \[0, 9\], got 10"):
        localise(hypothesis_particles(sc.hypotheses, 50, rng), sc.odometry, sc.ranges, sc.bearings, sc.walls,
                 sc.dt, rng, max_range_m=4.0, snapshots=(10,))


def test_the_unicycle_jacobian_and_the_range_jacobian_match_finite_differences():
    from quadlib.perception import scan_range_sensor, unicycle_model

    model = unicycle_model((0.05, 0.02))
    x, u, dt, eps = np.array([3.0, 2.0, 0.7]), np.array([0.8, 0.3]), 0.2, 1e-6
    fd = np.column_stack([(model.g(x + e, u, dt) - model.g(x - e, u, dt)) / (2 * eps) for e in np.eye(3) * eps])
    np.testing.assert_allclose(model.G(x, u, dt), fd, atol=1e-8)
    walls = room_map(20.0, 12.0, pillars=0)
    sensor = scan_range_sensor([0.0, np.pi / 2], walls, max_range_m=30.0, sigma_m=0.1)
    pose = np.array([5.0, 4.0, 0.0])  # beam 0 meets the east wall x = 20, beam 1 the north wall y = 12
    np.testing.assert_allclose(sensor.h(pose), [15.0, 8.0], atol=1e-12)
    np.testing.assert_allclose(sensor.H(pose)[:, :2], [[-1.0, 0.0], [0.0, -1.0]], atol=1e-6)
    turned = np.array([5.0, 4.0, 0.1])  # beam 0 at 0.1 rad: r = 15 / cos(0.1), dr/dψ = 15 sin / cos²
    assert sensor.H(turned)[0, 2] == pytest.approx(15 * np.sin(0.1) / np.cos(0.1) ** 2, rel=1e-6)


def test_an_ekf_finds_the_pose_only_from_the_right_corner():
    from quadlib import Measurements, ModelEKF, run_filter
    from quadlib.perception import scan_range_sensor, unicycle_model

    sc = corner_start(np.random.default_rng(17))
    t = np.arange(sc.truth.shape[0] + 1) * sc.dt
    u = np.vstack([sc.odometry, [np.nan, np.nan]])
    z = np.where(np.isnan(sc.ranges), sc.max_range_m, sc.ranges)
    scans = Measurements(scan_range_sensor(sc.bearings, sc.walls, sc.max_range_m, 0.5), t[1:], z)
    final = []
    for start in sc.hypotheses:
        ekf = ModelEKF(unicycle_model((0.05, 0.03)), start, np.diag([0.3, 0.3, 0.087]) ** 2, sc.dt)
        final.append(pose_error(run_filter(ekf, t, u, [scans]).x[-1], sc.truth[-1])[0])
    assert final[0] < 0.3 and min(final[1:]) > 5.0
