"""A particle filter: a belief made of weighted samples, which can hold several hypotheses at once.

Every belief after chapter 02 is one Gaussian. Localising against a known map from an ambiguous
start needs more: in a rectangular room, a robot that sees only a corner could be in any of the
four, and a Gaussian must pick one of them or sit in the middle, where nothing fits. A particle
filter keeps ``N`` poses ``xᵢ`` with weights ``wᵢ`` (summing to 1) and repeats:

1. **predict** — move every particle by the measured odometry plus a sample of its noise;
2. **update** — multiply each weight by the likelihood ``p(scan | xᵢ)`` and renormalise;
3. **resample** — when the effective sample size ``N_eff = 1 / Σ wᵢ²`` falls below a threshold
   (few particles carry the weight), draw ``N`` new particles in proportion to the weights.

The scan likelihood compares each beam's range with the range the map predicts from the
particle's pose (:func:`~quadlib.perception.lidar.cast_rays`). Both are clipped at the sensor's
maximum range (no return reads as the maximum), and each beam's density is a Gaussian of σ
``sigma_m`` mixed with a uniform floor ``outlier`` over ``[0, max_range]``: one bad beam or an
obstacle the map lacks then lowers a particle's weight instead of zeroing it. ``sigma_m`` is
deliberately wider than the lidar's noise: the particles are spread centimetres to decimetres
apart, and a likelihood as sharp as the sensor would give all the weight to the one nearest the
truth, collapsing the belief at the first update (what a too-sharp likelihood does is measured in
chapter 20).

Resampling draws from ``rng`` (filterpy's ``monte_carlo`` schemes draw from numpy's global random
state, which would make runs depend on what else used it): systematic (one uniform draw, ``N``
evenly spaced pointers), stratified (one draw per stratum), multinomial (``N`` independent draws),
and residual (the integer parts of ``N wᵢ`` kept, the rest drawn multinomially).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.geometry.rotations import wrap_angle
from quadlib.perception.lidar import cast_rays
from quadlib.validation import (
    as_count,
    as_finite_array,
    as_float_array,
    as_positive,
    as_probability,
    as_rng,
    as_vector,
)

__all__ = ["RESAMPLING_SCHEMES", "LocalisationRun", "effective_sample_size", "localise", "odometry_step",
           "particle_pose", "pose_error", "resample", "scan_log_likelihood"]

RESAMPLING_SCHEMES = ("systematic", "stratified", "multinomial", "residual")


def _weights(weights) -> np.ndarray:
    w = as_finite_array("weights", weights, ndim=1)
    if w.size == 0 or np.any(w < 0) or not w.sum() > 0:
        raise ValueError(f"weights: expected non-negative weights with a positive sum, got {w.size} weights "
                         f"summing to {w.sum() if w.size else 0.0:.3g} (min {w.min() if w.size else 0.0:.3g})")
    return w / w.sum()


def effective_sample_size(weights) -> float:
    """``N_eff = 1 / Σ wᵢ²`` of the normalised weights: ``N`` for equal weights, 1 when one
    particle has them all."""
    w = _weights(weights)
    return float(1.0 / np.sum(w * w))


def resample(weights, rng, scheme: str = "systematic") -> np.ndarray:
    """Indices (N,) of the particles drawn in proportion to ``weights`` by ``scheme`` (module
    documentation); the new weights are all ``1/N``."""
    w = _weights(weights)
    rng = as_rng(rng)
    if scheme not in RESAMPLING_SCHEMES:
        raise ValueError(f"scheme: expected one of {RESAMPLING_SCHEMES}, got {scheme!r}")
    n = w.size
    cumulative = np.cumsum(w)
    cumulative[-1] = 1.0  # guard against round-off below the last pointer
    if scheme == "systematic":
        pointers = (rng.random() + np.arange(n)) / n
    elif scheme == "stratified":
        pointers = (rng.random(n) + np.arange(n)) / n
    elif scheme == "multinomial":
        pointers = np.sort(rng.random(n))
    else:
        copies = np.floor(n * w).astype(int)
        kept = np.repeat(np.arange(n), copies)
        rest = n * w - copies
        if kept.size == n:
            return kept
        rest_cum = np.cumsum(rest / rest.sum())
        rest_cum[-1] = 1.0
        drawn = np.searchsorted(rest_cum, np.sort(rng.random(n - kept.size)), side="right")
        return np.concatenate([kept, drawn])
    return np.searchsorted(cumulative, pointers, side="right")


def _poses(name: str, value) -> np.ndarray:
    poses = as_finite_array(name, value, ndim=2)
    if poses.shape[1] != 3 or poses.shape[0] < 1:
        raise ValueError(f"{name}: expected poses (x, y, yaw) of shape (N, 3), got {poses.shape}")
    return poses


def odometry_step(particles, odometry, dt: float, rng, sigma) -> np.ndarray:
    """Particles (N, 3) moved by one odometry sample ``(v, ω)`` [m/s, rad/s] over ``dt`` [s]: each
    gets its own noisy ``v + σ_v n₁, ω + σ_ω n₂`` (``sigma = (σ_v, σ_ω)``) and drives straight
    along its heading turned by half the step's turn (the midpoint rule)."""
    p = _poses("particles", particles)
    v, w = as_vector("odometry", odometry, 2)
    dt = as_positive("dt", dt)
    sv, sw = as_vector("sigma", sigma, 2)
    if sv < 0 or sw < 0:
        raise ValueError(f"sigma: expected (σ_v, σ_ω) >= 0, got {(sv, sw)}")
    rng = as_rng(rng)
    n = p.shape[0]
    v_i = v + sv * rng.standard_normal(n)
    w_i = w + sw * rng.standard_normal(n)
    heading = p[:, 2] + 0.5 * w_i * dt
    return np.column_stack([p[:, 0] + v_i * dt * np.cos(heading), p[:, 1] + v_i * dt * np.sin(heading),
                            wrap_angle(p[:, 2] + w_i * dt)])


def scan_log_likelihood(particles, bearings, ranges, segments, *, max_range_m: float, sigma_m: float,
                        outlier: float = 0.05) -> np.ndarray:
    """``log p(ranges | particle)`` (N,) for a scan of ``ranges`` (B,) (NaN: no return) along
    ``bearings`` (B,) [rad] in the map ``segments`` (S, 2, 2): the robust beam model of the module
    documentation, beams independent."""
    p = _poses("particles", particles)
    bearings = as_finite_array("bearings", bearings, ndim=1)
    ranges = as_float_array("ranges", ranges)
    if ranges.shape != bearings.shape or np.any(np.isinf(ranges)) or np.any(ranges < 0):
        raise ValueError(f"ranges, bearings: expected ranges >= 0 (NaN for no return), one per bearing, got ranges "
                         f"of shape {ranges.shape} (min {np.nanmin(ranges, initial=np.inf):.3g}) for bearings of "
                         f"shape {bearings.shape}")
    seg = as_finite_array("segments", segments)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise ValueError(f"segments: expected wall segments of shape (S, 2, 2), got {seg.shape}")
    max_range = as_positive("max_range_m", max_range_m)
    sigma = as_positive("sigma_m", sigma_m)
    outlier = as_probability("outlier", outlier)
    expected = np.minimum(cast_rays(p[:, :2], p[:, 2], bearings, seg), max_range)
    observed = np.where(np.isnan(ranges), max_range, np.minimum(ranges, max_range))
    gauss = np.exp(-0.5 * ((observed - expected) / sigma) ** 2) / (np.sqrt(2.0 * np.pi) * sigma)
    return np.sum(np.log((1.0 - outlier) * gauss + outlier / max_range), axis=1)


def particle_pose(particles, weights) -> np.ndarray:
    """The weighted mean pose ``(x, y, yaw)``, the yaw averaged as a direction (its sines and
    cosines). Meaningful once the particles have gathered into one cluster."""
    p = _poses("particles", particles)
    w = _weights(weights)
    if w.size != p.shape[0]:
        raise ValueError(f"weights: expected one per particle ({p.shape[0]}), got {w.size}")
    return np.array([w @ p[:, 0], w @ p[:, 1], np.arctan2(w @ np.sin(p[:, 2]), w @ np.cos(p[:, 2]))])


def pose_error(estimate, truth) -> np.ndarray:
    """Distance [m] and absolute heading difference [rad] between poses ``(x, y, yaw)``, (K, 2) for
    (K, 3) inputs (or (2,) for one pose each)."""
    e = np.atleast_2d(as_finite_array("estimate", estimate))
    t = np.atleast_2d(as_finite_array("truth", truth))
    if e.shape != t.shape or e.shape[-1] != 3:
        raise ValueError(f"estimate, truth: expected poses (x, y, yaw) of the same shape, got {np.shape(estimate)} "
                         f"and {np.shape(truth)}")
    out = np.column_stack([np.hypot(*(e[:, :2] - t[:, :2]).T), np.abs(wrap_angle(e[:, 2] - t[:, 2]))])
    return out[0] if np.ndim(estimate) == 1 else out


@dataclass(frozen=True)
class LocalisationRun:
    """What :func:`localise` did at each scan: the mean ``pose`` (K, 3), the ``spread`` (K,) [m]
    (weighted RMS distance of the particles from it), the effective sample size ``ess`` (K,) after
    the update, whether it ``resampled`` (K,), the final ``particles`` (N, 3) and ``weights``, and
    ``snapshots``: step → (particles, weights) after that step's update, for the steps asked for."""

    pose: np.ndarray
    spread: np.ndarray
    ess: np.ndarray
    resampled: np.ndarray
    particles: np.ndarray
    weights: np.ndarray
    snapshots: dict


def localise(particles, odometry, scans, bearings, segments, dt: float, rng, *, odometry_sigma=(0.05, 0.02),
             max_range_m: float, sigma_m: float = 0.5, outlier: float = 0.05, scheme: str = "systematic",
             resample_below: float = 0.5, snapshots=()) -> LocalisationRun:
    """Run the particle filter from ``particles`` (N, 3) (the initial belief, equal weights) over
    ``K`` steps: ``odometry`` (K, 2) ``(v, ω)`` moves them, then ``scans`` (K, B) of ranges along
    ``bearings`` (B,) weigh them; resample by ``scheme`` when ``N_eff < resample_below · N``. The
    particles after the steps listed in ``snapshots`` are kept (for plots)."""
    p = _poses("particles", particles).copy()
    odo = as_finite_array("odometry", odometry, ndim=2)
    if odo.shape[1] != 2:
        raise ValueError(f"odometry: expected (v, ω) per step, shape (K, 2), got {odo.shape}")
    scans = as_float_array("scans", scans)
    if scans.ndim != 2 or scans.shape[0] != odo.shape[0]:
        raise ValueError(f"scans: expected one scan of ranges per odometry step, shape ({odo.shape[0]}, B), "
                         f"got {scans.shape}")
    resample_below = as_probability("resample_below", resample_below, open_interval=False)
    sigma = as_vector("odometry_sigma", odometry_sigma, 2)
    if np.any(sigma < 0):
        raise ValueError(f"odometry_sigma: expected (σ_v, σ_ω) >= 0, got {sigma.tolist()}")
    dt = as_positive("dt", dt)
    if scheme not in RESAMPLING_SCHEMES:
        raise ValueError(f"scheme: expected one of {RESAMPLING_SCHEMES}, got {scheme!r}")
    rng = as_rng(rng)
    n, k = p.shape[0], odo.shape[0]
    keep = set()
    for j, step in enumerate(snapshots):
        keep.add(as_count(f"snapshots[{j}]", step, low=0, high=k - 1))
    kept = {}
    log_w = np.full(n, -np.log(n))
    pose, spread, ess, resampled = np.zeros((k, 3)), np.zeros(k), np.zeros(k), np.zeros(k, dtype=bool)
    for j in range(k):
        p = odometry_step(p, odo[j], dt, rng, sigma)
        log_w = log_w + scan_log_likelihood(p, bearings, scans[j], segments, max_range_m=max_range_m,
                                            sigma_m=sigma_m, outlier=outlier)
        w = np.exp(log_w - log_w.max())
        w /= w.sum()
        pose[j] = particle_pose(p, w)
        spread[j] = np.sqrt(w @ np.sum((p[:, :2] - pose[j, :2]) ** 2, axis=1))
        ess[j] = 1.0 / np.sum(w * w)
        if j in keep:
            kept[j] = (p.copy(), w.copy())
        if ess[j] < resample_below * n:
            p, log_w, resampled[j] = p[resample(w, rng, scheme)], np.full(n, -np.log(n)), True
        else:
            log_w = np.log(w)
    return LocalisationRun(pose=pose, spread=spread, ess=ess, resampled=resampled, particles=p,
                           weights=np.exp(log_w - log_w.max()) / np.exp(log_w - log_w.max()).sum(), snapshots=kept)
