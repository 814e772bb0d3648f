"""Monocular visual odometry: the camera's motion from the features two images share (the blog's
"Visual Odometry" pipeline, after Scaramuzza and Fraundorfer 2011).

A pinhole camera (``z`` forward along the optical axis, ``x`` right, ``y`` down) with focal length
``f`` [px] and principal point ``(c_x, c_y)`` sees a point ``X = (X, Y, Z)`` of its own frame at pixel
``(f X/Z + c_x, f Y/Z + c_y)``. Between two views, a point's coordinates change as
``X₂ = R X₁ + t``; its normalised image coordinates ``x = K⁻¹ (u, v, 1)`` then satisfy the epipolar
constraint ``x₂ᵀ E x₁ = 0`` with the essential matrix ``E = [t]× R``.

* **Eight-point algorithm** — each pair gives one linear equation in the nine entries of ``E``
  (``kron(x₂, x₁) · vec(E) = 0``); with eight or more, ``E`` is the right singular vector of the
  smallest singular value, projected onto essential matrices (two equal singular values, one zero).
* **RANSAC** — mismatched features break least squares, so ``E`` is fitted to random minimal sets
  of eight and the one with the most pairs within a Sampson distance ``threshold`` wins; ``E`` is
  then refitted to those inliers.
* **Pose from E** — ``E = U diag(1, 1, 0) Vᵀ`` gives two rotations ``U W Vᵀ, U Wᵀ Vᵀ`` and ``t = ±u₃``;
  of the four, the one that puts triangulated points in front of both cameras is right. ``t`` comes
  out as a unit vector: one camera cannot tell a small motion near a small scene from a large one
  near a large scene (the **scale** problem).
* **Relative scale** — the distance between two points triangulated from views (k−1, k) and again
  from (k, k+1) must be the same: their ratio carries the scale from one step to the next. Only the
  first step's length must come from elsewhere (the IMU, a barometer, a known object).
* **Concatenation** — ``(R, t)`` map points from camera k−1 to camera k; the camera itself moves by
  the inverse, so its pose in the world is ``C_k = C_{k−1} [Rᵀ, −Rᵀ t s]``: the blog's
  ``C_k = C_{k−1} T_k`` with ``T_k`` that inverse (the errata appendix's table of what was checked).

numpy's SVD is all it needs (no OpenCV): the eight-point solver is a dozen lines, and a student
can read every one of them; OpenCV's five-point solver is faster and more robust, and would add a
large binary dependency for what the chapter teaches.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.validation import (
    as_count,
    as_finite_array,
    as_float_array,
    as_positive,
    as_probability,
    as_rng,
    as_vector,
)

__all__ = ["CAMERA_IN_BODY", "Camera", "VoRun", "decompose_essential", "essential_eight_point", "essential_ransac",
           "observe", "project", "recover_pose", "relative_scale", "textured_room", "triangulate", "visual_odometry"]

CAMERA_IN_BODY = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # columns: camera x, y, z in FRD


@dataclass(frozen=True)
class Camera:
    """A pinhole camera: focal length ``f_px`` [px], image ``width`` × ``height`` [px], principal
    point at the centre."""

    f_px: float = 400.0
    width: int = 640
    height: int = 480

    def __post_init__(self):
        as_positive("Camera.f_px", self.f_px)
        for name in ("width", "height"):  # [px]
            object.__setattr__(self, name, as_count(f"Camera.{name}", getattr(self, name)))

    @property
    def K(self) -> np.ndarray:
        """The intrinsic matrix."""
        return np.array([[self.f_px, 0.0, self.width / 2], [0.0, self.f_px, self.height / 2], [0.0, 0.0, 1.0]])

    def normalised(self, pixels) -> np.ndarray:
        """Normalised homogeneous coordinates (N, 3) ``K⁻¹ (u, v, 1)`` of ``pixels`` (N, 2)."""
        uv = _pairs("pixels", pixels, 2)
        return np.column_stack([(uv[:, 0] - self.width / 2) / self.f_px, (uv[:, 1] - self.height / 2) / self.f_px,
                                np.ones(len(uv))])


def _pairs(name: str, value, d: int) -> np.ndarray:
    arr = as_finite_array(name, value, ndim=2)
    if arr.shape[1] != d:
        raise ValueError(f"{name}: expected shape (N, {d}), got {arr.shape}")
    return arr


def _matched(x1, x2, minimum: int = 8, stacks: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Checked ``x1, x2``: (N, 3) each, or with ``stacks`` also (M, N, 3) each."""
    if stacks and np.ndim(x1) == 3:
        x1, x2 = as_finite_array("x1", x1, ndim=3), as_finite_array("x2", x2, ndim=3)
    else:
        x1, x2 = _pairs("x1", x1, 3), _pairs("x2", x2, 3)
    if x1.shape != x2.shape or x1.shape[-1] != 3 or x1.shape[-2] < minimum:
        stack = " (or stacks (M, N, 3))" if stacks else ""
        raise ValueError(f"x1, x2: expected at least {minimum} matched points of shape (N, 3) each{stack}, got "
                         f"{x1.shape} and {x2.shape}")
    return x1, x2


def textured_room(rng, size_m=(60.0, 60.0, 12.0), points: int = 3000) -> np.ndarray:
    """Landmarks (N, 3) in NED scattered evenly (by area) over the walls, floor (``down = 0``) and
    ceiling of a box room centred on the origin, ``size_m = (north, east, height)``: the texture a
    camera tracks. (Points on one plane alone would defeat the eight-point algorithm: a plane's
    images fit a family of essential matrices.)"""
    rng = as_rng(rng)
    size = as_vector("size_m", size_m, 3)
    if np.any(size <= 0):
        raise ValueError(f"size_m: expected three positive lengths, got {size.tolist()}")
    points = as_count("points", points, low=4)
    n_len, e_len, h = size
    faces = np.array([e_len * h, e_len * h, n_len * h, n_len * h, n_len * e_len, n_len * e_len])
    face = rng.choice(6, size=points, p=faces / faces.sum())
    u = rng.uniform(-0.5, 0.5, (points, 3)) * size  # a point in the box, then pushed onto its face
    u[:, 2] -= h / 2
    u[face == 0, 0], u[face == 1, 0] = n_len / 2, -n_len / 2
    u[face == 2, 1], u[face == 3, 1] = e_len / 2, -e_len / 2
    u[face == 4, 2], u[face == 5, 2] = 0.0, -h
    return u


def project(landmarks, R_nc, p_n, camera: Camera, rng, *, pixel_sigma: float = 0.0,
            min_depth_m: float = 0.5) -> tuple[np.ndarray, np.ndarray]:
    """Pixels (N, 2) of ``landmarks`` (N, 3, NED) seen by ``camera`` at position ``p_n`` with
    orientation ``R_nc`` (camera axes in NED), plus white pixel noise; and which are visible
    (N,) — in front by ``min_depth_m`` and inside the image."""
    X = _pairs("landmarks", landmarks, 3)
    R = as_finite_array("R_nc", R_nc, ndim=2)
    if R.shape != (3, 3):
        raise ValueError(f"R_nc: expected a 3 × 3 rotation, got shape {R.shape}")
    p = as_vector("p_n", p_n, 3)
    if not isinstance(camera, Camera):
        raise TypeError(f"camera: expected a Camera, got {type(camera).__name__}")
    sigma = as_positive("pixel_sigma", pixel_sigma, allow_zero=True)
    min_depth = as_positive("min_depth_m", min_depth_m)
    rng = as_rng(rng)
    Xc = (X - p) @ R
    depth = Xc[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = camera.f_px * Xc[:, :2] / depth[:, None] + [camera.width / 2, camera.height / 2]
    uv = uv + sigma * rng.standard_normal(uv.shape)
    visible = (depth > min_depth) & (uv[:, 0] >= 0) & (uv[:, 0] < camera.width) & (uv[:, 1] >= 0) & \
        (uv[:, 1] < camera.height)
    return np.where(visible[:, None], uv, np.nan), visible


def observe(landmarks, R_nc, p_n, camera: Camera, rng, *, pixel_sigma: float = 0.5,
            mismatch: float = 0.0) -> np.ndarray:
    """Pixels (K, N, 2) of ``landmarks`` (N, 3) in ``K`` frames taken from orientations ``R_nc``
    (K, 3, 3) and positions ``p_n`` (K, 3) (:func:`project`; NaN where not seen); a share
    ``mismatch`` of the seen ones is matched wrongly (moved to a random pixel), as a feature
    matcher sometimes does — in each frame, so a pair of frames shares about ``(1 − mismatch)²``
    good matches."""
    R = as_finite_array("R_nc", R_nc, ndim=3)
    p = as_finite_array("p_n", p_n, ndim=2)
    if R.shape[1:] != (3, 3) or p.shape != (R.shape[0], 3):
        raise ValueError(f"R_nc, p_n: expected (K, 3, 3) and (K, 3), got {R.shape} and {p.shape}")
    if mismatch != 0.0:
        mismatch = as_probability("mismatch", mismatch)
    rng = as_rng(rng)
    frames = []
    for Rk, pk in zip(R, p, strict=True):
        uv, seen = project(landmarks, Rk, pk, camera, rng, pixel_sigma=pixel_sigma)
        wrong = seen & (rng.random(seen.size) < mismatch)
        uv[wrong] = rng.uniform([0.0, 0.0], [camera.width, camera.height], (int(wrong.sum()), 2))
        frames.append(uv)
    return np.array(frames)


def essential_eight_point(x1, x2) -> np.ndarray:
    """``E`` (3, 3, unit Frobenius norm) from ≥ 8 matched normalised points ``x1, x2`` (N, 3) by
    least squares (module documentation). For stacks of M point sets (M, N, 3) it returns the M fits
    (M, 3, 3) from one call, bit for bit the fits one by one (RANSAC fits its minimal sets so)."""
    x1, x2 = _matched(x1, x2, stacks=True)
    A = np.einsum("...ni,...nj->...nij", x2, x1).reshape(x1.shape[:-1] + (9,))
    # the right singular vector of the smallest singular value: with nine rows or more the reduced
    # SVD has all nine (the same bits, without the N × N left factor: 3 ms → 50 µs for 300 points)
    E = np.linalg.svd(A, full_matrices=A.shape[-2] < 9)[2][..., -1, :].reshape(x1.shape[:-2] + (3, 3))
    U, _, Vt = np.linalg.svd(E)
    return U @ np.diag([1.0, 1.0, 0.0]) @ Vt / np.sqrt(2.0)


def _sampson(E, x1, x2):
    """The squared Sampson distance of each pair (N,), or (M, N) for a stack of ``E`` (M, 3, 3)."""
    Ex1, Etx2 = x1 @ np.swapaxes(E, -1, -2), x2 @ E
    num = np.einsum("ni,...ni->...n", x2, Ex1) ** 2
    return num / (Ex1[..., 0] ** 2 + Ex1[..., 1] ** 2 + Etx2[..., 0] ** 2 + Etx2[..., 1] ** 2)


def essential_ransac(x1, x2, rng, *, threshold: float = 1e-3, iterations: int = 500,
                     confidence: float = 0.999) -> tuple[np.ndarray, np.ndarray]:
    """``E`` and the inlier mask (N,) by RANSAC over minimal sets of eight, ``threshold`` on the
    Sampson distance in normalised coordinates (about pixels / f). Eight noisy points give a rough
    ``E``, so each new best is refitted to all its inliers, again while that gains inliers (the
    "locally optimised" RANSAC of Chum et al. 2003), and the final ``E`` to the last inliers. It
    stops after ``iterations``, or once a minimal set free of outliers has been drawn with
    probability ``confidence``, given the best inlier share ``w`` so far (``log(1 − confidence) /
    log(1 − w⁸)`` draws), but not before 100: a clean set of eight noisy points can still give a
    poor ``E``."""
    x1, x2 = _matched(x1, x2)
    threshold = as_positive("threshold", threshold)
    iterations = as_count("iterations", iterations)
    confidence = as_probability("confidence", confidence)
    rng = as_rng(rng)
    best, needed, fitted = np.zeros(len(x1), dtype=bool), iterations, []
    for i in range(iterations):
        if i >= needed:
            break
        if i == len(fitted):  # the first 100 draws always happen (needed ≥ 100): fit them as one stack
            picks = np.array([rng.choice(len(x1), 8, replace=False) for _ in range(min(100, iterations) if i == 0
                                                                                    else 1)])
            fitted.extend(_sampson(essential_eight_point(x1[picks], x2[picks]), x1, x2))
        d2 = fitted[i]
        if np.sum(d2 < threshold**2) <= best.sum():
            continue
        for _ in range(10):  # a new best: refit to the pairs within a wider gate, then within the threshold
            wide = d2 < (3.0 * threshold) ** 2
            if wide.sum() < 8:
                break
            d2 = _sampson(essential_eight_point(x1[wide], x2[wide]), x1, x2)
            inliers = d2 < threshold**2
            if inliers.sum() <= best.sum():
                break
            best = inliers
            clean = min((best.sum() / len(x1)) ** 8, 1.0 - 1e-12)
            needed = min(needed, max(100, int(np.ceil(np.log(1.0 - confidence) / np.log1p(-clean)))))
    if best.sum() < 8:
        raise ValueError(f"x1, x2: expected at least 8 pairs consistent with one motion, got {int(best.sum())} "
                         f"of {len(x1)} within threshold {threshold:g}")
    E = essential_eight_point(x1[best], x2[best])
    return E, _sampson(E, x1, x2) < threshold**2


def decompose_essential(E) -> list[tuple[np.ndarray, np.ndarray]]:
    """The four ``(R, t)`` (``t`` unit) an essential matrix allows."""
    E = as_finite_array("E", E, ndim=2)
    if E.shape != (3, 3):
        raise ValueError(f"E: expected a 3 × 3 matrix, got shape {E.shape}")
    U, _, Vt = np.linalg.svd(E)
    U, Vt = U * np.sign(np.linalg.det(U)), Vt * np.sign(np.linalg.det(Vt))  # proper rotations
    W = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    t = U[:, 2]
    return [(U @ W @ Vt, t), (U @ W @ Vt, -t), (U @ W.T @ Vt, t), (U @ W.T @ Vt, -t)]


def triangulate(R, t, x1, x2) -> np.ndarray:
    """Points (N, 3) in camera 1's frame from their normalised images in cameras 1 (pose ``I, 0``)
    and 2 (``X₂ = R X₁ + t``), by linear least squares (the DLT)."""
    x1, x2 = _matched(x1, x2, minimum=1)
    P1, P2 = np.hstack([np.eye(3), np.zeros((3, 1))]), np.hstack([R, np.reshape(t, (3, 1))])
    A = np.stack([x1[:, :1] * P1[2] - P1[0], x1[:, 1:2] * P1[2] - P1[1],
                  x2[:, :1] * P2[2] - P2[0], x2[:, 1:2] * P2[2] - P2[1]], axis=1)  # (N, 4, 4)
    X = np.linalg.svd(A)[2][:, -1]
    return X[:, :3] / X[:, 3:]


def recover_pose(E, x1, x2) -> tuple[np.ndarray, np.ndarray]:
    """The ``(R, t)`` of :func:`decompose_essential` that puts the most triangulated points in
    front of both cameras; ``t`` unit."""
    x1, x2 = _matched(x1, x2, minimum=1)
    best, count = None, -1
    for R, t in decompose_essential(E):
        X1 = triangulate(R, t, x1, x2)
        front = int(np.sum((X1[:, 2] > 0) & ((X1 @ R.T + t)[:, 2] > 0)))
        if front > count:
            best, count = (R, t), front
    return best


def relative_scale(previous, current) -> float:
    """The scale of the current step: ``previous`` (N, 3) are points triangulated from views
    (k−1, k) at that step's (known) scale, ``current`` (N, 3) the same points triangulated from
    (k, k+1) with a unit translation, both in frame k. Each point's distance from camera k is the
    same in both: the median ratio of the distances is the step's length."""
    a, b = _pairs("previous", previous, 3), _pairs("current", current, 3)
    if a.shape != b.shape or a.shape[0] < 1:
        raise ValueError(f"previous, current: expected the same points, at least one, got shapes {a.shape} and "
                         f"{b.shape}")
    da, db = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    keep = db > 1e-12
    return float(np.median(da[keep] / db[keep]))


def _parallax(R, t, X):
    """The angle [rad] at each point (N, 3, camera 1's frame) between the rays from the two cameras."""
    c2 = -R.T @ t
    a, b = X, X - c2
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ni,ni->n", a, b))


@dataclass(frozen=True)
class VoRun:
    """What :func:`visual_odometry` estimated: camera positions ``p_n`` (K, 3) and orientations
    ``R_nc`` (K, 3, 3) in the world, the ``scale`` [m] of each step (K − 1,) and the RANSAC
    ``inliers`` per step."""

    p_n: np.ndarray
    R_nc: np.ndarray
    scale: np.ndarray
    inliers: np.ndarray


def visual_odometry(ids, pixels, camera: Camera, scale_m, rng, *, R_nc0=None, p_n0=None,
                    threshold_px: float = 2.0, min_parallax_rad: float = 0.02) -> VoRun:
    """Chain the pipeline over ``K`` frames: ``pixels`` (K, N, 2) of landmarks ``ids`` (N,) (NaN
    where not seen). Each step: the pairs both frames see, E by RANSAC, (R, t), the step's length,
    and the concatenation. ``scale_m`` gives the lengths: one number is the first step's, and each
    later one comes from the relative scale of the points the previous step triangulated (the
    blog's step 5); an array (K − 1,) gives every step's length from another sensor (the speed
    an INS or a flow sensor measures, times the frame interval). Starts at ``R_nc0, p_n0`` (default
    the identity and the origin). The relative scale uses the points whose rays meet at more than
    ``min_parallax_rad`` in both steps (far points, seen at nearly the same angle, have depths too
    noisy to carry it); all of them if none do."""
    uv = as_float_array("pixels", pixels)  # NaN: not seen
    ids = np.asarray(ids)
    if uv.ndim != 3 or uv.shape[2] != 2 or uv.shape[0] < 2 or ids.shape != (uv.shape[1],) or np.isinf(uv).any():
        raise ValueError(f"pixels, ids: expected pixels (K >= 2, N, 2) and ids (N,), got {uv.shape} and {ids.shape}")
    if not isinstance(camera, Camera):
        raise TypeError(f"camera: expected a Camera, got {type(camera).__name__}")
    lengths = as_finite_array("scale_m", scale_m)
    if lengths.shape not in ((), (uv.shape[0] - 1,)) or np.any(lengths <= 0):
        raise ValueError(f"scale_m: expected the first step's length or one per step ({uv.shape[0] - 1},), all "
                         f"positive [m], got shape {lengths.shape}")
    threshold = as_positive("threshold_px", threshold_px) / camera.f_px
    min_parallax = as_positive("min_parallax_rad", min_parallax_rad, allow_zero=True)
    rng = as_rng(rng)
    R_nc = np.eye(3) if R_nc0 is None else as_finite_array("R_nc0", R_nc0, ndim=2)
    if R_nc.shape != (3, 3):
        raise ValueError(f"R_nc0: expected a 3 × 3 rotation, got shape {R_nc.shape}")
    p_n = np.zeros(3) if p_n0 is None else as_vector("p_n0", p_n0, 3)
    k_frames = uv.shape[0]
    positions, rotations, scales, inliers = [p_n], [R_nc], [], []
    previous = None  # (ids, points in the current frame at the current scale) from the last step
    for k in range(1, k_frames):
        both = ~np.isnan(uv[k - 1, :, 0]) & ~np.isnan(uv[k, :, 0])
        x1, x2 = camera.normalised(uv[k - 1, both]), camera.normalised(uv[k, both])
        E, good = essential_ransac(x1, x2, rng, threshold=threshold)
        R, t = recover_pose(E, x1[good], x2[good])
        X = triangulate(R, t, x1[good], x2[good])  # in frame k−1, unit baseline
        seen, wide = ids[both][good], _parallax(R, t, X) > min_parallax
        if lengths.ndim or previous is None:
            s = float(lengths[k - 1] if lengths.ndim else lengths)
        else:
            common, i_old, i_new = np.intersect1d(previous[0], seen, return_indices=True)
            if common.size < 1:
                raise ValueError(f"pixels: expected a landmark seen in frames {k - 2}, {k - 1} and {k} for the "
                                 f"relative scale, got none")
            both_wide = previous[2][i_old] & wide[i_new]
            use = both_wide if both_wide.any() else np.ones(common.size, dtype=bool)
            s = relative_scale(previous[1][i_old][use], X[i_new][use])
        previous = (seen, (X @ R.T + t) * s, wide)  # the points in frame k, at the true scale
        p_n = p_n + R_nc @ (-R.T @ t * s)
        R_nc = R_nc @ R.T
        positions.append(p_n)
        rotations.append(R_nc)
        scales.append(s)
        inliers.append(int(good.sum()))
    return VoRun(p_n=np.array(positions), R_nc=np.array(rotations), scale=np.array(scales),
                 inliers=np.array(inliers))
