"""Iterative closest point: the rigid transform that lays one scan onto another (the blog's third
pipeline, "Iterative Closest Point"), in 2D and 3D.

Each iteration pairs every source point with its nearest target point (scipy's ``cKDTree``), drops
the worst pairs (``trim``), and solves for the transform that best aligns the pairs, in one of two
ways:

* **point to point** — minimise ``Σ |R pᵢ + t − qᵢ|²`` exactly: with the centroids ``μ_p, μ_q`` and
  ``H = Σ (pᵢ − μ_p)(qᵢ − μ_q)ᵀ = U Σ Vᵀ``, ``R = V D Uᵀ`` with ``D = diag(1, …, 1, det(V Uᵀ))`` and
  ``t = μ_q − R μ_p``. Without ``D`` (the blog writes ``R = V Uᵀ``) a flat or noisy scan can give a
  reflection (the errata appendix, E26).
* **point to plane** — minimise ``Σ ((R pᵢ + t − qᵢ)·nᵢ)²``, the distance to the target's local
  surface, linearised in a small rotation ``δθ``: ``R pᵢ ≈ pᵢ + δθ × pᵢ`` gives one linear equation
  per pair, ``[(pᵢ × nᵢ)ᵀ, nᵢᵀ] [δθ; t] = (qᵢ − pᵢ)·nᵢ``, solved by least squares (in 2D the rotation
  is one angle and ``pᵢ × nᵢ`` its z component). The step is applied as an exact rotation.

The result carries the information of the transform, ``JᵀJ / σ²``, with ``J`` the residuals'
Jacobian at the solution and ``σ²`` their mean square, and its covariance, the (pseudo-)inverse.
Both are over (rotation, translation), the rotation taken about the source's origin (for a scan,
the sensor) so that the translation's block is the uncertainty of where the sensor is: for a
residual ``R pᵢ + t − qᵢ`` a small turn ``δθ`` moves the matched point by ``δθ × (R pᵢ)``, not by
``δθ × (R pᵢ + t)``. A corridor, whose walls say nothing about the position along it, shows up as
no information (a zero eigenvalue, a huge or undefined variance) in that direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from quadlib.kernels.quaternion import skew
from quadlib.validation import as_count, as_finite_array, as_positive, as_probability

__all__ = ["IcpResult", "best_rigid_transform", "convergence_basin", "estimate_normals", "icp", "point_to_plane_step"]


@dataclass(frozen=True)
class IcpResult:
    """What :func:`icp` found: ``R`` (d, d) and ``t`` (d,) with ``target ≈ R source + t``; the number
    of ``iterations``; whether it ``converged``; the ``rmse`` of the kept pairs [m]; the ``covariance``
    of (rotation about the source's origin, translation) — (1 + 2) in 2D, (3 + 3) in 3D — and its
    ``information``, whose zero eigenvalues mark directions the scans cannot fix (module documentation)."""

    R: np.ndarray
    t: np.ndarray
    iterations: int
    converged: bool
    rmse: float
    information: np.ndarray
    covariance: np.ndarray


def _points(name: str, value) -> np.ndarray:
    pts = as_finite_array(name, value, ndim=2)
    if pts.shape[1] not in (2, 3) or pts.shape[0] < pts.shape[1]:
        raise ValueError(f"{name}: expected at least d points of dimension d = 2 or 3, shape (N, d), got {pts.shape}")
    return pts


def best_rigid_transform(p, q) -> tuple[np.ndarray, np.ndarray]:
    """``R, t`` minimising ``Σ |R pᵢ + t − qᵢ|²`` for paired points ``p, q`` (N, d): the SVD solution
    with the reflection guard (module documentation)."""
    p, q = _points("p", p), _points("q", q)
    if p.shape != q.shape:
        raise ValueError(f"p, q: expected paired points of the same shape, got {p.shape} and {q.shape}")
    mu_p, mu_q = p.mean(axis=0), q.mean(axis=0)
    U, _, Vt = np.linalg.svd((p - mu_p).T @ (q - mu_q))
    D = np.eye(p.shape[1])
    D[-1, -1] = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
    R = Vt.T @ D @ U.T
    return R, mu_q - R @ mu_p


def _rotation(theta: np.ndarray) -> np.ndarray:
    """The rotation of angle ``theta`` (2D, one element) or rotation vector (3D), exactly."""
    if theta.size == 1:
        c, s = np.cos(theta[0]), np.sin(theta[0])
        return np.array([[c, -s], [s, c]])
    angle = float(np.linalg.norm(theta))
    K = skew(theta)
    if angle < 1e-12:
        return np.eye(3) + K
    return np.eye(3) + np.sin(angle) / angle * K + (1.0 - np.cos(angle)) / angle**2 * K @ K


def _cross_n(p: np.ndarray, n: np.ndarray) -> np.ndarray:
    return (p[:, 0] * n[:, 1] - p[:, 1] * n[:, 0])[:, None] if p.shape[1] == 2 else np.cross(p, n)


def point_to_plane_step(p, q, normals) -> tuple[np.ndarray, np.ndarray]:
    """One linearised point-to-plane step for paired points and the target's unit normals (N, d):
    the least-squares ``[δθ; t]`` of ``[(pᵢ × nᵢ)ᵀ, nᵢᵀ] [δθ; t] = (qᵢ − pᵢ)·nᵢ``, returned as ``R, t``."""
    p, q, n = _points("p", p), _points("q", q), _points("normals", normals)
    if not p.shape == q.shape == n.shape:
        raise ValueError(f"p, q, normals: expected the same shape, got {p.shape}, {q.shape}, {n.shape}")
    A = np.hstack([_cross_n(p, n), n])
    b = np.einsum("ij,ij->i", q - p, n)
    x = np.linalg.lstsq(A, b, rcond=None)[0]
    k = 1 if p.shape[1] == 2 else 3
    return _rotation(x[:k]), x[k:]


def estimate_normals(points, neighbours: int = 8) -> np.ndarray:
    """Unit surface normals (N, d): the direction of least spread of each point's ``neighbours``
    nearest points (the smallest eigenvector of their covariance)."""
    pts = _points("points", points)
    neighbours = as_count("neighbours", neighbours, low=pts.shape[1], high=pts.shape[0])
    _, idx = cKDTree(pts).query(pts, k=neighbours)
    local = pts[idx] - pts[idx].mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", local, local))
    return vectors[:, :, 0]


def _information(lever, normals, residuals) -> np.ndarray:
    """``JᵀJ / σ²`` over (rotation, translation); ``lever`` (N, d) = ``R pᵢ``, the matched points
    relative to the source's origin; ``σ²`` at least (1 µm)² (noise-free data)."""
    d = lever.shape[1]
    if normals is None:  # point to point: residual R p + t − q, Jacobian [−[Rp]×, I] (3D) or [perp(Rp), I] (2D)
        if d == 2:
            J = np.zeros((2 * len(lever), 3))
            J[0::2, 0], J[1::2, 0] = -lever[:, 1], lever[:, 0]
            J[0::2, 1], J[1::2, 2] = 1.0, 1.0
        else:
            J = np.zeros((3 * len(lever), 6))
            for i, pm in enumerate(lever):
                J[3 * i:3 * i + 3, :3] = -skew(pm)
                J[3 * i:3 * i + 3, 3:] = np.eye(3)
    else:
        J = np.hstack([_cross_n(lever, normals), normals])
    sigma2 = max(float(np.mean(residuals**2)), 1e-12)
    return J.T @ J / sigma2


def _rotation_angle(R: np.ndarray) -> float:
    """The angle of a 2D or 3D rotation matrix [rad], accurate near zero: ``atan2(sin, cos)`` with
    ``sin = ‖R − Rᵀ‖_F / (2√2)`` and ``cos = (trace R − (d − 2)) / 2``. (``arccos`` of the cosine alone
    loses every angle below about 1e-8 rad to rounding, so a tolerance smaller than that could be met
    or missed by the last bit of the trace.)"""
    d = R.shape[0]
    return float(np.arctan2(np.linalg.norm(R - R.T) / (2.0 * np.sqrt(2.0)), (np.trace(R) - (d - 2)) / 2.0))


def icp(source, target, *, method: str = "point", initial=None, max_iterations: int = 50, tolerance: float = 1e-10,
        trim: float = 0.0, target_normals=None) -> IcpResult:
    """Align ``source`` (N, d) to ``target`` (M, d): ``target ≈ R source + t``.

    Parameters
    ----------
    method : {"point", "plane"}
        Point-to-point (exact SVD step) or point-to-plane (linearised step, needs normals).
    initial : (R, t), optional
        Start from this transform; default the identity.
    max_iterations : int
    tolerance : float
        Stop when an iteration moves the transform by less than this (rotation [rad] plus
        translation [m]).
    trim : float in [0, 1)
        Fraction of the pairs with the largest distances dropped each iteration (outliers, parts
        of a scan the other does not see).
    target_normals : (M, d) array_like, optional
        For ``"plane"``; estimated with :func:`estimate_normals` when not given.
    """
    src, tgt = _points("source", source), _points("target", target)
    d = src.shape[1]
    if tgt.shape[1] != d:
        raise ValueError(f"target: expected points of dimension {d} like source, got shape {tgt.shape}")
    if method not in ("point", "plane"):
        raise ValueError(f"method: expected 'point' or 'plane', got {method!r}")
    max_iterations = as_count("max_iterations", max_iterations)
    tolerance = as_positive("tolerance", tolerance)
    if trim != 0.0:
        trim = as_probability("trim", trim)
    normals = None
    if method == "point" and target_normals is not None:
        raise ValueError("target_normals: expected them only with method='plane', got normals for method='point'")
    if method == "plane":
        normals = estimate_normals(tgt) if target_normals is None else _points("target_normals", target_normals)
        if normals.shape != tgt.shape:
            raise ValueError(f"target_normals: expected one per target point, shape {tgt.shape}, got {normals.shape}")
    if initial is None:
        R, t = np.eye(d), np.zeros(d)
    else:
        try:
            R, t = (as_finite_array("initial", a) for a in initial)
        except (TypeError, ValueError) as err:
            raise ValueError(f"initial: expected (R, t) of shapes ({d}, {d}) and ({d},), got {initial!r:.60}") from err
        if R.shape != (d, d) or t.shape != (d,):
            raise ValueError(f"initial: expected (R, t) of shapes ({d}, {d}) and ({d},), got {R.shape}, {t.shape}")
    tree = cKDTree(tgt)
    keep_n = max(d + 1, int(round((1.0 - trim) * src.shape[0])))
    converged, iterations = False, 0
    while iterations < max_iterations:
        iterations += 1
        moved = src @ R.T + t
        dist, idx = tree.query(moved)
        keep = np.argsort(dist, kind="stable")[:keep_n]
        if normals is None:
            dR, dt = best_rigid_transform(moved[keep], tgt[idx[keep]])
        else:
            dR, dt = point_to_plane_step(moved[keep], tgt[idx[keep]], normals[idx[keep]])
        R, t = dR @ R, dR @ t + dt
        change = _rotation_angle(dR) + float(np.linalg.norm(dt))
        if change < tolerance:
            converged = True
            break
    moved = src @ R.T + t
    dist, idx = tree.query(moved)
    keep = np.argsort(dist, kind="stable")[:keep_n]
    lever = moved[keep] - t
    if normals is None:
        info = _information(lever, None, (moved[keep] - tgt[idx[keep]]).ravel())
    else:
        matched_normals = normals[idx[keep]]
        info = _information(lever, matched_normals, np.einsum("ij,ij->i", moved[keep] - tgt[idx[keep]],
                                                              matched_normals))
    return IcpResult(R=R, t=t, iterations=iterations, converged=converged,
                     rmse=float(np.sqrt(np.mean(dist[keep] ** 2))), information=info, covariance=np.linalg.pinv(info))


def convergence_basin(scans, rotations_rad, shifts_m, method: str, *, angle_tol_rad: float = 0.0087,
                      shift_tol_m: float = 0.05, max_iterations: int = 100) -> tuple[np.ndarray, np.ndarray]:
    """How far from the truth ICP may start and still find it, in 2D. ``scans`` is a list of pairs
    ``(source, target)`` of the same scene from the same pose; each source starts turned by each of
    ``rotations_rad`` and shifted by each of ``shifts_m`` (in a direction that changes from pair to
    pair). Returns the share of pairs that end within ``angle_tol_rad`` (0.5°) and ``shift_tol_m``
    of the identity, and their median iteration count, both (rotations, shifts)."""
    rotations = as_finite_array("rotations_rad", rotations_rad, ndim=1)
    shifts = as_finite_array("shifts_m", shifts_m, ndim=1)
    pairs = list(scans)
    if not pairs:
        raise ValueError("scans: expected at least one (source, target) pair, got none")
    for k, pair in enumerate(pairs):
        shapes = [np.shape(a) for a in pair] if isinstance(pair, (tuple, list)) else None
        if shapes is None or len(shapes) != 2 or any(len(sh) != 2 or sh[0] < 3 or sh[1] != 2 for sh in shapes):
            raise ValueError(f"scans[{k}]: expected a pair (source, target) of 2D scans of at least 3 points, shapes "
                             f"(n, 2), got {shapes if shapes is not None else type(pair).__name__}")
    found, iterations = np.zeros((rotations.size, shifts.size)), np.zeros((rotations.size, shifts.size))
    for i, a in enumerate(rotations):
        R0 = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        for j, shift in enumerate(shifts):
            ok, its = 0, []
            for k, (source, target) in enumerate(pairs):
                t0 = shift * np.array([np.cos(k), np.sin(k)])
                r = icp(source, target, method=method, initial=(R0, t0), max_iterations=max_iterations)
                ok += abs(np.arctan2(r.R[1, 0], r.R[0, 0])) < angle_tol_rad and np.linalg.norm(r.t) < shift_tol_m
                its.append(r.iterations)
            found[i, j], iterations[i, j] = ok / len(pairs), np.median(its)
    return found, iterations
