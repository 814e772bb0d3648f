"""Accuracy and consistency metrics: RMSE, NEES, NIS and their χ² bounds.

For a consistent filter the estimation error ``e = x - x̂`` is zero-mean with
covariance ``P``, so the normalised estimation error squared

.. math::  \\epsilon_k = e_k^\\top P_k^{-1} e_k

is χ²-distributed with ``n`` degrees of freedom; likewise the normalised
innovation squared ``ν_k = y_kᵀ S_k⁻¹ y_k`` with ``k`` = measurement size.
Averaged over ``M`` Monte Carlo runs, ``M·ε̄`` is χ² with ``M·n`` dof
(Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking
and Navigation*, 2001, §5.4).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import chi2

from quadlib.geometry.quaternion import (
    as_unit_quaternions,
    quat_conjugate,
    quat_multiply,
    quat_to_rotvec,
)
from quadlib.geometry.rotations import wrap_angle
from quadlib.validation import (
    as_count,
    as_finite_array,
    as_finite_number,
    as_float_array,
    as_mask,
    as_positive,
    as_probability,
    as_quaternions,
    as_times,
)

__all__ = ["angle_error", "angle_rmse", "attitude_error", "attitude_rmse", "broad_errors", "chi2_interval",
           "fraction_inside", "nees", "nis", "rmse", "settling_time"]


def rmse(error, axis: int | None = 0) -> np.ndarray:
    """Root-mean-square of ``error`` along ``axis``, ignoring NaN entries.

    Parameters
    ----------
    error : array_like
        Estimation errors (estimate minus truth), any shape.
    axis : int or None
        Axis to average over (default 0: over time, one value per state).
    """
    err = as_float_array("error", error)
    if err.size == 0:
        raise ValueError("error: expected a non-empty array, got size 0")
    return np.sqrt(np.nanmean(err**2, axis=axis))


def angle_error(estimate, truth) -> np.ndarray:
    """``estimate − truth`` wrapped to (−π, π] [rad]: the error of an angle (yaw, Euler angles)."""
    est, tru = as_float_array("estimate", estimate), as_float_array("truth", truth)
    if est.shape != tru.shape:
        raise ValueError(f"estimate, truth: expected the same shape, got {est.shape} and {tru.shape}")
    return wrap_angle(est - tru)


def angle_rmse(estimate, truth, axis: int | None = 0) -> np.ndarray:
    """RMSE of angles [rad], each error wrapped to (−π, π] first (:func:`angle_error`)."""
    return rmse(angle_error(estimate, truth), axis=axis)


def attitude_error(q_estimate, q_truth) -> np.ndarray:
    """Angle of the rotation between estimated and true attitudes, ``|rotvec(q_true⁻¹ ⊗ q_est)|``
    [rad] in [0, π], ``(N,)`` for ``(N, 4)`` unit quaternions (either sign; non-unit ones are refused)."""
    q_e, q_t = as_unit_quaternions("q_estimate", q_estimate), as_unit_quaternions("q_truth", q_truth)
    if q_e.shape != q_t.shape:
        raise ValueError(f"q_estimate, q_truth: expected the same shape, got {q_e.shape} and {q_t.shape}")
    return np.linalg.norm(quat_to_rotvec(quat_multiply(quat_conjugate(q_t), q_e)), axis=-1)


def broad_errors(q_estimate, q_truth, movement=None) -> dict[str, float]:
    """BROAD's orientation errors [deg] (Laidig et al., *Data* 2021, §4; their evaluation code).

    .. math::

        q_e = \\hat q \\otimes q^{-1}, \\quad
        e_{total} = 2\\arccos|w|, \\quad e_{heading} = 2\\arctan|z/w|, \\quad
        e_{inclination} = 2\\arccos\\sqrt{w^2 + z^2}

    ``q_e`` is the error in the *earth* frame, so its rotation about the vertical (z, in NED as in
    BROAD's ENU) is the heading error and the rest the inclination error. Each is the RMS over the
    ``movement`` samples, skipping rows where the truth is NaN; the earth frames are compared as
    they are (no heading offset is removed: the estimator must find north itself).

    Parameters
    ----------
    q_estimate, q_truth : (N, 4) array_like
        ``q_nb`` estimates and truth, scalar first (the truth may have NaN rows).
    movement : (N,) bool array_like, optional
        The samples that count (default: all).

    Returns
    -------
    dict with ``total_deg``, ``heading_deg``, ``inclination_deg``
    """
    q_est = as_quaternions("q_estimate", q_estimate)
    q_true = np.asarray(q_truth, dtype=float)
    if q_true.shape != q_est.shape or q_est.ndim != 2:
        raise ValueError(f"q_estimate, q_truth: expected the same (N, 4) shape, got {q_est.shape} and {q_true.shape}")
    mask = np.ones(len(q_est), bool) if movement is None else as_mask("movement", movement, len(q_est))
    keep = mask & ~np.isnan(q_true).any(axis=1)
    if not keep.any():
        raise ValueError("movement, q_truth: expected at least one moving sample with a truth, got none")
    e = quat_multiply(q_est[keep] / np.linalg.norm(q_est[keep], axis=1, keepdims=True),
                      quat_conjugate(q_true[keep] / np.linalg.norm(q_true[keep], axis=1, keepdims=True)))
    w, z = np.abs(e[:, 0]), np.abs(e[:, 3])
    errors = {"total_deg": 2 * np.arccos(np.clip(w, 0.0, 1.0)),
              "heading_deg": 2 * np.arctan2(z, w),
              "inclination_deg": 2 * np.arccos(np.clip(np.sqrt(w**2 + z**2), 0.0, 1.0))}
    return {k: float(np.degrees(np.sqrt(np.mean(v**2)))) for k, v in errors.items()}


def attitude_rmse(q_estimate, q_truth) -> float:
    """RMS of :func:`attitude_error` over all samples [rad]."""
    return float(rmse(attitude_error(q_estimate, q_truth), axis=None))


def _quadratic_forms(name_e: str, e, name_P: str, P) -> np.ndarray:
    e = as_finite_array(name_e, e)
    P = as_finite_array(name_P, P)
    if e.ndim == 1:
        e = e[:, None]
    if e.ndim != 2:
        raise ValueError(f"{name_e}: expected shape (N, n), got {e.shape}")
    N, n = e.shape
    if P.shape == (n, n):
        P = np.broadcast_to(P, (N, n, n))
    if P.shape != (N, n, n):
        raise ValueError(f"{name_P}: expected shape ({N}, {n}, {n}) to match {name_e}, got {P.shape}")
    smallest = np.linalg.eigvalsh(0.5 * (P + np.swapaxes(P, -1, -2))).min(axis=-1)
    if np.any(smallest <= 0):
        k = int(np.argmax(smallest <= 0))
        raise ValueError(f"{name_P}: expected positive definite matrices, got smallest eigenvalue {smallest[k]:.3g} "
                         f"at index {k}")
    return np.einsum("ki,ki->k", e, np.linalg.solve(P, e[..., None])[..., 0])


def nees(error, P) -> np.ndarray:
    """Normalised estimation error squared per step.

    Parameters
    ----------
    error : (N, n) array_like
        Estimate minus truth (angle components already wrapped).
    P : (N, n, n) or (n, n) array_like
        Filter covariances.

    Returns
    -------
    (N,) ndarray
    """
    return _quadratic_forms("error", error, "P", P)


def nis(innovation, S) -> np.ndarray:
    """Normalised innovation squared per sample; rows with NaN give NaN.

    Parameters
    ----------
    innovation : (K, k) array_like
    S : (K, k, k) array_like
    """
    y = as_float_array("innovation", innovation)
    y = y[:, None] if y.ndim == 1 else y
    S = as_float_array("S", S)
    out = np.full(y.shape[0], np.nan)
    ok = ~np.isnan(y).any(axis=1)
    if S.ndim == 1:
        S = S[:, None, None]
    if S.shape[0] != y.shape[0]:
        raise ValueError(f"S: expected {y.shape[0]} matrices to match innovation, got shape {S.shape}")
    if ok.any():
        out[ok] = _quadratic_forms("innovation", y[ok], "S", S[ok])
    return out


def chi2_interval(dof: int, n_runs: int = 1, probability: float = 0.95) -> tuple[float, float]:
    """Two-sided χ² interval for a NEES/NIS value averaged over ``n_runs`` runs.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one value (state or measurement size).
    n_runs : int
        Number of Monte Carlo runs averaged (1 for a single run).
    probability : float
        Probability mass inside the interval.

    Returns
    -------
    (low, high) : tuple of float
        Bounds for the *average*: ``χ²⁻¹((1∓p)/2, M·dof) / M``.
    """
    dof, n_runs = as_count("dof", dof), as_count("n_runs", n_runs)
    p = as_probability("probability", probability)
    total = dof * n_runs
    low = chi2.ppf((1 - p) / 2, total) / n_runs
    high = chi2.ppf((1 + p) / 2, total) / n_runs
    return float(low), float(high)


def fraction_inside(values, bounds: tuple[float, float]) -> float:
    """Share of the finite ``values`` that lie within ``bounds`` (inclusive)."""
    v = as_float_array("values", values)
    v = v[np.isfinite(v)]
    if v.size == 0:
        raise ValueError("values: expected at least one finite value, got none")
    b = as_float_array("bounds", bounds)
    if b.shape != (2,) or np.isnan(b).any():
        raise ValueError(f"bounds: expected (low, high), got {bounds!r}")
    low, high = b
    if not low <= high:
        raise ValueError(f"bounds: expected low <= high, got {bounds}")
    return float(np.mean((v >= low) & (v <= high)))


def settling_time(t, estimate, target: float, tolerance: float, t_start: float) -> float:
    """Time after ``t_start`` until ``estimate`` enters and stays within ``target ± tolerance``.

    Parameters
    ----------
    t : (N,) times [s]
    estimate : (N,) estimates
    target : float
        Value the estimate should settle to.
    tolerance : float
        Half-width of the band (same unit as ``estimate``), > 0.
    t_start : float
        Time of the change [s].

    Returns
    -------
    float
        Seconds from ``t_start``; ``inf`` if the estimate is outside the band at the last sample.
    """
    t = as_times("t", t)
    x = as_finite_array("estimate", estimate, ndim=1)
    if x.shape != t.shape:
        raise ValueError(f"estimate: expected shape {t.shape} to match t, got {x.shape}")
    tolerance, target = as_positive("tolerance", tolerance), as_finite_number("target", target)
    t_start = as_finite_number("t_start", t_start)
    after = t >= t_start
    outside = after & (np.abs(x - target) > tolerance)
    if not after.any():
        raise ValueError(f"t_start: expected a time within t, got {t_start!r} after the last sample")
    if outside[-1]:
        return float("inf")
    if not outside.any():
        return 0.0
    last_out = np.flatnonzero(outside)[-1]
    return float(t[last_out + 1] - t_start)
