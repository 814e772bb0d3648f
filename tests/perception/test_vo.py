"""Visual odometry: the essential matrix, the pose it gives, RANSAC against mismatches, the
relative scale, and the chained pipeline."""

import numpy as np
import pytest

from quadlib.geometry.quaternion import quat_to_dcm
from quadlib.perception import (
    CAMERA_IN_BODY,
    Camera,
    decompose_essential,
    essential_eight_point,
    essential_ransac,
    observe,
    project,
    recover_pose,
    relative_scale,
    textured_room,
    triangulate,
    visual_odometry,
)
from quadlib.perception.vo import _sampson
from quadlib.quad import figure_eight

CAM = Camera()
LANDMARKS = textured_room(np.random.default_rng(0))


def _angle(a, b):
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), np.dot(a, b)))


def _rotation(rotvec):
    from quadlib.geometry.quaternion import quat_from_rotvec
    return quat_to_dcm(quat_from_rotvec(rotvec))


def _pair(R_nc1, p1, R_nc2, p2, sigma=0.0, rng=None):
    rng = rng or np.random.default_rng(1)
    uv1, seen1 = project(LANDMARKS, R_nc1, p1, CAM, rng, pixel_sigma=sigma)
    uv2, seen2 = project(LANDMARKS, R_nc2, p2, CAM, rng, pixel_sigma=sigma)
    both = seen1 & seen2
    R, t = R_nc2.T @ R_nc1, R_nc2.T @ (np.asarray(p1) - np.asarray(p2))  # X₂ = R X₁ + t
    return CAM.normalised(uv1[both]), CAM.normalised(uv2[both]), R, t


MOTIONS = [  # camera 1 looking north from 2 m up; camera 2 moved forward, sideways, up, and turned
    ([0.5, 0.0, 0.0], [0.0, 0.0, 0.0]), ([0.0, 0.4, 0.0], [0.0, 0.05, 0.0]), ([0.3, -0.2, -0.1], [0.02, -0.1, 0.03]),
    ([-0.2, 0.1, 0.2], [0.0, 0.0, 0.3]),
]


@pytest.mark.parametrize(("move", "turn"), MOTIONS)
def test_noise_free_features_give_the_relative_pose_exactly(move, turn):
    R1 = CAMERA_IN_BODY
    p1 = np.array([0.0, 0.0, -2.0])
    R2 = _rotation(turn) @ R1
    x1, x2, R_true, t_true = _pair(R1, p1, R2, p1 + move)
    assert len(x1) > 100
    E = essential_eight_point(x1, x2)
    assert np.abs(np.einsum("ni,ij,nj->n", x2, E, x1)).max() < 1e-12  # the epipolar constraint
    R, t = recover_pose(E, x1, x2)
    assert np.abs(R - R_true).max() <= 1e-9
    assert _angle(t, t_true) <= 1e-9 and np.linalg.norm(t) == pytest.approx(1.0)


def test_the_eight_point_solution_is_the_full_svds_bit_for_bit():
    """With more than eight pairs the reduced SVD is used (no N × N left factor); its last right
    singular vector is the full SVD's, to the bit — chapter 19's stored outputs rely on it."""
    rng = np.random.default_rng(3)
    x1, x2, _, _ = _pair(CAMERA_IN_BODY, [0.0, 0.0, -2.0], _rotation([0.02, -0.1, 0.03]) @ CAMERA_IN_BODY,
                         [0.3, -0.2, -2.1], sigma=1.0, rng=rng)
    for n in (8, 9, 20, len(x1)):
        for _ in range(20):
            pick = rng.choice(len(x1), n, replace=False)
            A = np.einsum("ni,nj->nij", x2[pick], x1[pick]).reshape(-1, 9)
            E = np.linalg.svd(A)[2][-1].reshape(3, 3)  # the full SVD, as the method is written
            U, _, Vt = np.linalg.svd(E)
            np.testing.assert_array_equal(essential_eight_point(x1[pick], x2[pick]),
                                          U @ np.diag([1.0, 1.0, 0.0]) @ Vt / np.sqrt(2.0))


@pytest.mark.parametrize("n", [8, 9, 30])
def test_a_stack_of_point_sets_gives_the_fits_one_by_one_bit_for_bit(n):
    """RANSAC fits its first hundred minimal sets as one stack: each fit must be the one it would get
    alone, bit for bit, so that the same inliers win."""
    rng = np.random.default_rng(4)
    x1, x2, _, _ = _pair(CAMERA_IN_BODY, [0.0, 0.0, -2.0], _rotation([0.02, -0.1, 0.03]) @ CAMERA_IN_BODY,
                         [0.3, -0.2, -2.1], sigma=1.0, rng=rng)
    picks = np.array([rng.choice(len(x1), n, replace=False) for _ in range(50)])
    stacked = essential_eight_point(x1[picks], x2[picks])
    assert stacked.shape == (50, 3, 3)
    for pick, E in zip(picks, stacked, strict=True):
        np.testing.assert_array_equal(E, essential_eight_point(x1[pick], x2[pick]))


def test_stacks_of_points_must_match_and_hold_eight_pairs():
    x = np.zeros((4, 8, 3))
    with pytest.raises(ValueError, match=r"x1, x2: expected at least 8 matched points .* got \(4, 7, 3\) and"):
        essential_eight_point(x[:, :7], x[:, :7])
    with pytest.raises(ValueError, match=r"got \(4, 8, 3\) and \(3, 8, 3\)"):
        essential_eight_point(x, x[:3])
    with pytest.raises(ValueError, match=r"got \(4, 8, 2\)"):
        essential_eight_point(x[..., :2], x[..., :2])


def test_the_four_decompositions_hold_the_truth_once_and_triangulation_is_exact():
    x1, x2, R_true, t_true = _pair(CAMERA_IN_BODY, [0.0, 0.0, -2.0], CAMERA_IN_BODY, [0.6, 0.2, -2.0])
    options = decompose_essential(essential_eight_point(x1, x2))
    matches = [i for i, (R, t) in enumerate(options) if np.abs(R - R_true).max() < 1e-9 and _angle(t, t_true) < 1e-9]
    assert len(matches) == 1 and all(abs(np.linalg.det(R) - 1.0) < 1e-12 for R, _ in options)
    scale = np.linalg.norm(t_true)
    X1 = triangulate(R_true, t_true / scale, x1, x2) * scale
    np.testing.assert_allclose(X1[:, :2] / X1[:, 2:], x1[:, :2], atol=1e-9)  # reprojects onto its pixels
    assert np.all(X1[:, 2] > 0.5)


def test_points_on_one_plane_leave_the_eight_point_system_underdetermined():
    wall = LANDMARKS[LANDMARKS[:, 0] == LANDMARKS[:, 0].max()]  # the north wall only
    rng = np.random.default_rng(0)
    uv1, s1 = project(wall, CAMERA_IN_BODY, [0.0, 0.0, -2.0], CAM, rng)
    uv2, s2 = project(wall, CAMERA_IN_BODY, [0.5, 0.3, -2.0], CAM, rng)
    x1, x2 = CAM.normalised(uv1[s1 & s2]), CAM.normalised(uv2[s1 & s2])
    singular = np.linalg.svd(np.einsum("ni,nj->nij", x2, x1).reshape(-1, 9), compute_uv=False)
    assert singular[-2] < 1e-9 * singular[0]  # two (in fact three) null directions, not one


def test_ransac_keeps_the_consistent_pairs_and_rejects_mismatches():
    rng = np.random.default_rng(2)
    x1, x2, R_true, t_true = _pair(CAMERA_IN_BODY, [0.0, 0.0, -2.0], _rotation([0, 0, 0.1]) @ CAMERA_IN_BODY,
                                   [1.0, 0.3, -2.0], sigma=0.5, rng=rng)
    wrong = rng.random(len(x1)) < 0.3
    x2_bad = x2.copy()
    x2_bad[wrong] = CAM.normalised(rng.uniform([0, 0], [CAM.width, CAM.height], (int(wrong.sum()), 2)))
    # 2 px, 4σ of one image's noise (the Sampson distance spans both images)
    E, inliers = essential_ransac(x1, x2_bad, rng, threshold=2.0 / CAM.f_px)
    assert inliers[~wrong].mean() > 0.9 and inliers[wrong].mean() < 0.05
    R, t = recover_pose(E, x1[inliers], x2_bad[inliers])
    assert np.degrees(_angle(t, t_true)) < 2.0 and np.abs(R - R_true).max() < 5e-3
    least_squares = essential_eight_point(x1, x2_bad)
    assert np.median(_sampson(least_squares, x1[~wrong], x2[~wrong])) > 10 * np.median(_sampson(E, x1[~wrong],
                                                                                                  x2[~wrong]))


def test_relative_scale_is_the_ratio_of_distances():
    X = np.random.default_rng(3).normal(size=(20, 3)) + [0, 0, 8]
    assert relative_scale(X * 2.5, X) == pytest.approx(2.5)


def _flight_frames(every=25):
    flight = figure_eight(width_m=20.0, period_s=20.0, altitude_m=3.0, duration_s=20.0, rate_hz=50.0)
    k = np.arange(0, flight.t.size, every)
    return quat_to_dcm(flight.q_nb[k]) @ CAMERA_IN_BODY, flight.pos[k]


def test_noise_free_odometry_with_the_first_step_only_retraces_the_flight():
    R_nc, p_n = _flight_frames()
    pixels = observe(LANDMARKS, R_nc, p_n, CAM, np.random.default_rng(4), pixel_sigma=0.0)
    run = visual_odometry(np.arange(len(LANDMARKS)), pixels, CAM, np.linalg.norm(p_n[1] - p_n[0]),
                          np.random.default_rng(5), R_nc0=R_nc[0], p_n0=p_n[0])
    np.testing.assert_allclose(run.p_n, p_n, atol=1e-6)
    np.testing.assert_allclose(run.R_nc, R_nc, atol=1e-9)


def test_noisy_odometry_drifts_a_few_percent_of_the_distance():
    R_nc, p_n = _flight_frames()
    steps = np.linalg.norm(np.diff(p_n, axis=0), axis=1)
    pixels = observe(LANDMARKS, R_nc, p_n, CAM, np.random.default_rng(6), pixel_sigma=0.5, mismatch=0.05)
    ids = np.arange(len(LANDMARKS))
    relative = visual_odometry(ids, pixels, CAM, steps[0], np.random.default_rng(7), R_nc0=R_nc[0], p_n0=p_n[0])
    measured = visual_odometry(ids, pixels, CAM, steps, np.random.default_rng(7), R_nc0=R_nc[0], p_n0=p_n[0])
    path = steps.sum()
    assert 0.0 < np.linalg.norm(measured.p_n[-1] - p_n[-1]) / path < 0.03
    assert 0.0 < np.linalg.norm(relative.p_n[-1] - p_n[-1]) / path < 0.10
    np.testing.assert_allclose(measured.scale, steps)


def test_bad_inputs_are_named():
    with pytest.raises(ValueError, match="Camera.width: expected an int"):
        Camera(width=0)
    with pytest.raises(ValueError, match="x1, x2: expected at least 8 matched points"):
        essential_eight_point(np.ones((5, 3)), np.ones((5, 3)))
    R_nc, p_n = _flight_frames(every=250)
    pixels = observe(LANDMARKS, R_nc, p_n, CAM, np.random.default_rng(0))
    with pytest.raises(ValueError, match="scale_m: expected the first step's length or one per step"):
        visual_odometry(np.arange(len(LANDMARKS)), pixels, CAM, [1.0, 2.0, 3.0, 4.0, 5.0], np.random.default_rng(0))
