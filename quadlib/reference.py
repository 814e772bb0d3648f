"""Textbook filters in plain numpy, line by line after Tellex et al. Algorithms 2 and 3.

These functions are for reading and for checking. Chapter 06 shows the Kalman filter's next to the
printed pseudocode, and the tests prove that quadlib's filterpy wrappers give the same numbers. For real
work use :class:`~quadlib.filters.ModelEKF` and :class:`~quadlib.filters.ModelUKF`, which add
input checks, gating, angle residuals and multi-rate replay.

Each function takes a :class:`~quadlib.model.Model` or :class:`~quadlib.model.Sensor` and plain
arrays, and returns new arrays: a mean of shape ``(n,)`` and a covariance ``(n, n)``. The Kalman
filter's two steps use the book's letters (chapter 00): estimate ``x``, ``P``; prior ``x_bar``,
``P_bar``; Jacobians ``G``, ``H``; innovation ``y``, its covariance ``S``; gain ``K``. The UKF's keep
the source's ``mu``, ``Sigma`` (Tellex's μ, Σ for the same mean and covariance), to be read beside
Algorithm 3 as printed (chapter 07 writes its own, in the book's letters). The corrections of the
errata appendix are applied (E2/E3 in Algorithm 2; E5–E7 in Algorithm 3).
"""

from __future__ import annotations

import numpy as np

from quadlib.model import Model, Sensor

__all__ = ["ekf_predict", "ekf_update", "sigma_points", "ukf_predict", "ukf_update"]


def ekf_predict(model: Model, x, P, u, dt: float):
    """Algorithm 2, PREDICT (lines 1–5): the prior ``x̄ = g(x, u, Δt)`` and ``P̄ = G P Gᵀ + Q``, with
    the Jacobian ``G`` taken at the previous estimate ``x``. For a linear model, ``g(x, u, Δt)`` is
    ``G x + B u`` and these are the Kalman filter's lines."""
    G = model.G(x, u, dt)
    x_bar = model.g(x, u, dt)
    P_bar = G @ P @ G.T + model.Q(dt)
    return x_bar, P_bar


def ekf_update(sensor: Sensor, x_bar, P_bar, z, joseph: bool = False):
    """Algorithm 2, UPDATE (lines 6–11), for a sensor with the plain residual ``z - h(x̄)``: the
    innovation ``y``, its covariance ``S``, the gain ``K`` and the posterior ``x``, ``P``, with the
    Jacobian ``H`` taken at the prior ``x̄``.

    ``joseph=False`` uses line 10 as printed, ``P = (I - K H) P̄``; ``joseph=True`` uses
    ``(I - K H) P̄ (I - K H)ᵀ + K R Kᵀ``, equal in exact arithmetic and symmetric by construction.
    """
    _require_plain_residual(sensor)
    H, R = sensor.H(x_bar), sensor.R
    y = z - sensor.h(x_bar)
    S = H @ P_bar @ H.T + R
    K = P_bar @ H.T @ np.linalg.inv(S)
    x = x_bar + K @ y
    I_KH = np.eye(x.size) - K @ H
    if joseph:
        return x, I_KH @ P_bar @ I_KH.T + K @ R @ K.T
    return x, I_KH @ P_bar


def sigma_points(mu, Sigma, alpha: float, beta: float, kappa: float):
    """Eqs. (5)–(10): the ``2N + 1`` sigma points (rows of ``X``) and their weights.

    Returns
    -------
    X : (2N+1, N) ndarray
        ``μ``, then ``μ + γ S_i`` and ``μ - γ S_i`` for the columns ``S_i`` of ``S``, a square
        root of ``Σ`` (here the lower Cholesky factor, ``S Sᵀ = Σ``).
    wm, wc : (2N+1,) ndarray
        Weights for the mean (eq. 7) and for the covariance (eq. 8).
    """
    N = mu.size
    lam = alpha**2 * (N + kappa) - N  # eq. (10)
    gamma = np.sqrt(N + lam)  # eq. (9)
    S = np.linalg.cholesky(Sigma)  # eq. (5)
    X = np.vstack([mu, mu + gamma * S.T, mu - gamma * S.T])  # eq. (6); row i of S.T is column S_i
    wm = np.full(2 * N + 1, 1.0 / (2.0 * (N + lam)))
    wm[0] = lam / (N + lam)  # eq. (7)
    wc = wm.copy()
    wc[0] += 1.0 - alpha**2 + beta  # eq. (8)
    return X, wm, wc


def ukf_predict(model: Model, mu, Sigma, u, dt: float, alpha: float, beta: float, kappa: float):
    """Algorithm 3, lines 3–9: propagate the sigma points through ``g``; their weighted mean and
    covariance plus ``Q`` are the prior (line 9 with the propagated points ``X̄``, see E5)."""
    X, wm, wc = sigma_points(mu, Sigma, alpha, beta, kappa)
    X_bar = np.array([model.g(x, u, dt) for x in X])  # line 5
    mu_bar = wm @ X_bar  # line 8
    D = X_bar - mu_bar
    return mu_bar, D.T @ (wc[:, None] * D) + model.Q(dt)  # line 9


def ukf_update(sensor: Sensor, mu_bar, Sigma_bar, z, alpha: float, beta: float, kappa: float):
    """Algorithm 3, lines 10–17, with the sigma points redrawn from ``(μ̄, Σ̄)`` (see E6), all
    ``2N + 1`` of them (E5), and ``Σ = Σ̄ - K Σᶻ Kᵀ`` (line 16; E7 for the blog's version)."""
    _require_plain_residual(sensor)
    X, wm, wc = sigma_points(mu_bar, Sigma_bar, alpha, beta, kappa)
    Z = np.array([sensor.h(x) for x in X])  # line 10
    mu_z = wm @ Z  # line 11
    dZ, dX = Z - mu_z, X - mu_bar
    S_z = dZ.T @ (wc[:, None] * dZ) + sensor.R  # line 12
    S_xz = dX.T @ (wc[:, None] * dZ)  # line 13
    K = S_xz @ np.linalg.inv(S_z)  # line 14
    return mu_bar + K @ (z - mu_z), Sigma_bar - K @ S_z @ K.T  # lines 15–16


def _require_plain_residual(sensor: Sensor) -> None:
    if sensor.residual is not np.subtract or sensor.mean is not None:
        raise ValueError(
            f"sensor: the reference filters support the plain residual z - h(x) only; {sensor.name!r} "
            "has a custom residual or mean (use ModelEKF / ModelUKF)"
        )
