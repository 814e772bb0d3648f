"""The one-number Kalman filter of chapter 03: a drone's height from a rangefinder, and its slider.

A drone is commanded a climb rate ``u`` [m/s]; its real climb rate differs from the command by
white noise, so over a step Δt its height [m, positive up] changes by ``u Δt`` plus a random
amount of standard deviation ``sigma_q`` [m]; once in the flight a gust nobody commanded lifts it
by ``gust_m``. A downward rangefinder measures the height at every step with noise ``sigma_r`` [m].
The filter tracks one number, the height ``x``, and its variance ``P``:

.. math::

    \\bar x = x + u\\,\\Delta t, \\quad \\bar P = P + Q; \\qquad
    K = \\frac{\\bar P}{\\bar P + R}, \\quad x = \\bar x + K (z - \\bar x), \\quad P = (1 - K)\\,\\bar P

with :math:`Q = \\sigma_q^2` and :math:`R = \\sigma_r^2` as the filter *assumes* them.

* :func:`climb_flight` simulates the flight (the chapter's first random draw, so
  ``climb_flight(np.random.default_rng(3))`` is the chapter's flight).
* :func:`one_number_trial` runs filterpy's ``KalmanFilter`` (``dim_x=1``) over that flight with an
  assumed ``sigma_q``, ``sigma_r`` and initial estimate ``x0 ± sigma0``, and returns a
  :class:`OneNumberTrial` for :func:`~quadlib.teaching.tuning.show_trial` and
  :func:`~quadlib.teaching.tuning.tuning_sliders`.

Source: Tellex et al. §3, Algorithm 2 with :math:`G = H = 1`; §2, Algorithm 1 for a Gaussian belief.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.validation import as_count, as_finite_number, as_positive, as_rng

__all__ = ["ClimbFlight", "OneNumberTrial", "climb_flight", "one_number_trial"]

TRUE_SIGMA_Q_M, TRUE_SIGMA_R_M = 0.03, 0.3  # the flight's process σ per step and rangefinder σ [m]
CHAPTER_SEED = 3  # chapter 03's SEED: its first draw is the flight


def _climb_command(t: np.ndarray) -> np.ndarray:
    """Hover 5 s, climb at 1 m/s for 5 s, hover, descend at 0.5 m/s from 30 s to 36 s, hover."""
    return np.select([(t >= 5.0) & (t < 10.0), (t >= 30.0) & (t < 36.0)], [1.0, -0.5], 0.0)


@dataclass(frozen=True)
class ClimbFlight:
    """One simulated flight: times ``t`` [s] (step ``dt``), the commanded climb rate ``u`` [m/s]
    (``u[k]`` holds from ``t[k]`` to ``t[k + 1]``), the gust's climb rate ``gust_rate`` [m/s]
    (the part of the motion nobody commanded, apart from the noise), the true height ``truth``
    [m] and the rangefinder's samples ``z`` [m], one per time; and the true ``sigma_q`` (the
    height's random change per step, m) and ``sigma_r`` (the rangefinder's noise, m)."""

    t: np.ndarray
    u: np.ndarray
    gust_rate: np.ndarray
    truth: np.ndarray
    z: np.ndarray
    sigma_q: float
    sigma_r: float

    @property
    def dt(self) -> float:
        """The step [s]."""
        return float(self.t[1] - self.t[0])


def climb_flight(rng, sigma_q: float = TRUE_SIGMA_Q_M, sigma_r: float = TRUE_SIGMA_R_M, gust_m: float = 1.0,
                 start_m: float = 2.0, duration_s: float = 40.0, dt: float = 0.1) -> ClimbFlight:
    """Simulate chapter 03's flight: hover at ``start_m``, a commanded climb of 5 m, a gust, a
    commanded descent of 3 m.

    .. math::  h_k = h_{k-1} + (u_{k-1} + g_{k-1})\\,\\Delta t + w_k, \\quad w_k \\sim \\mathcal N(0, \\sigma_q^2),
               \\qquad z_k = h_k + v_k, \\quad v_k \\sim \\mathcal N(0, \\sigma_r^2)

    Parameters
    ----------
    rng : numpy.random.Generator
        Draws first the process noise (``N - 1`` values), then the rangefinder's noise (``N``).
    sigma_q : float
        Standard deviation of the height's uncommanded change over one step [m].
    sigma_r : float
        Standard deviation of the rangefinder's noise [m].
    gust_m : float
        Height the gust adds [m] (any sign; 0 for none), as a climb rate shaped like half a sine
        between 22 s and 24 s (nothing when the flight is shorter).
    start_m : float
        True height at ``t = 0`` [m].
    duration_s, dt : float
        Length of the flight and step [s]; ``duration_s`` must hold at least two steps.
    """
    rng = as_rng(rng)
    sigma_q, sigma_r = as_positive("sigma_q", sigma_q), as_positive("sigma_r", sigma_r)
    gust_m, start_m = as_finite_number("gust_m", gust_m), as_finite_number("start_m", start_m)
    duration_s, dt = as_positive("duration_s", duration_s), as_positive("dt", dt)
    if duration_s < 2 * dt:
        raise ValueError(f"duration_s: expected at least two steps of dt = {dt:g} s, got {duration_s!r}")
    t = np.arange(round(duration_s / dt) + 1) * dt
    u = _climb_command(t)
    gust_start, gust_length = 22.0, 2.0
    inside = (t >= gust_start) & (t < gust_start + gust_length)
    gust_rate = np.where(inside, gust_m * np.pi / (2 * gust_length) * np.sin(np.pi * (t - gust_start) / gust_length),
                         0.0)
    w = sigma_q * rng.standard_normal(t.size - 1)
    truth = start_m + np.concatenate([[0.0], np.cumsum((u[:-1] + gust_rate[:-1]) * dt + w)])
    z = truth + sigma_r * rng.standard_normal(t.size)
    return ClimbFlight(t=t, u=u, gust_rate=gust_rate, truth=truth, z=z, sigma_q=sigma_q, sigma_r=sigma_r)


@dataclass(frozen=True)
class OneNumberTrial:
    """The one-number filter on one :class:`ClimbFlight` with an assumed ``sigma_q`` and
    ``sigma_r`` [m] and initial estimate ``x0`` ± ``sigma0`` [m]: the posterior estimate ``x`` and
    variance ``P`` after each sample, and the gain ``K`` each sample got."""

    sigma_q: float
    sigma_r: float
    x0: float
    sigma0: float
    flight: ClimbFlight
    x: np.ndarray
    P: np.ndarray
    K: np.ndarray

    @property
    def error(self) -> np.ndarray:
        """Estimate minus truth [m]."""
        return self.x - self.flight.truth

    @property
    def rmse(self) -> float:
        """RMS error [m] after the first 5 s."""
        return float(np.sqrt(np.mean(self.error[self.flight.t >= 5.0] ** 2)))

    @property
    def inside(self) -> float:
        """Share of the times whose truth lies inside the estimate's ±2σ band."""
        return float(np.mean(np.abs(self.error) <= 2.0 * np.sqrt(self.P)))

    def summary(self) -> str:
        f = self.flight
        return (f"assumed σ_q = {self.sigma_q:.3g} m, σ_r = {self.sigma_r:.3g} m (true {f.sigma_q:.3g} m, "
                f"{f.sigma_r:.3g} m), start {self.x0:.3g} ± {self.sigma0:.3g} m (true {f.truth[0]:.3g} m): "
                f"RMSE {100 * self.rmse:.1f} cm after 5 s, truth inside ±2σ {self.inside:.0%} of the time, "
                f"final gain K = {self.K[-1]:.3f}")

    def draw(self, fig) -> None:
        """The estimate with its ±2σ band against the truth and the samples, and its error against
        the band, side by side on ``fig``."""
        f, sigma = self.flight, np.sqrt(self.P)
        left, right = fig.subplots(1, 2)
        left.plot(f.t, f.z, ".", ms=2, color="0.65", label="rangefinder")
        left.plot(f.t, f.truth, "k", lw=1.2, label="truth")
        left.plot(f.t, self.x, "C0", lw=1.2, label="estimate")
        left.fill_between(f.t, self.x - 2 * sigma, self.x + 2 * sigma, color="C0", alpha=0.25, lw=0, label="±2σ")
        left.set(xlabel="t [s]", ylabel="height [m]", title="Estimate and truth")
        left.legend(fontsize="small", loc="upper left")
        right.fill_between(f.t, -2 * sigma, 2 * sigma, color="C0", alpha=0.25, lw=0, label="±2σ the filter claims")
        right.plot(f.t, self.error, "C3", lw=1, label="estimate − truth")
        right.axhline(0.0, color="0.4", lw=0.6)
        limit = max(0.5, float(np.percentile(np.abs(self.error), 99)) * 1.2)
        right.set(xlabel="t [s]", ylabel="error [m]", ylim=(-limit, limit), title="Error against the claimed band")
        right.legend(fontsize="small", loc="lower right")


def one_number_trial(sigma_q: float, sigma_r: float, x0: float = 2.0, sigma0: float = 0.5,
                     seed: int = CHAPTER_SEED) -> OneNumberTrial:
    """Run filterpy's ``KalmanFilter`` (``dim_x=1``) with ``Q = sigma_q²`` and ``R = sigma_r²`` [m²]
    from ``x0`` ± ``sigma0`` [m] over ``climb_flight(np.random.default_rng(seed))`` (the true
    σ_q = 0.03 m and σ_r = 0.3 m): the sample at ``t = 0`` updates the initial belief, and every
    later step predicts with the command, then updates."""
    from filterpy.kalman import KalmanFilter

    sigma_q, sigma_r = as_positive("sigma_q", sigma_q), as_positive("sigma_r", sigma_r)
    x0, sigma0 = as_finite_number("x0", x0), as_positive("sigma0", sigma0)
    flight = climb_flight(np.random.default_rng(as_count("seed", seed, 0)))
    kf = KalmanFilter(dim_x=1, dim_z=1, dim_u=1)
    kf.x, kf.P = np.array([[x0]]), np.array([[sigma0**2]])
    kf.F, kf.B, kf.H = np.eye(1), np.array([[flight.dt]]), np.eye(1)
    kf.Q, kf.R = np.array([[sigma_q**2]]), np.array([[sigma_r**2]])
    n = flight.t.size
    x, P, K = np.empty(n), np.empty(n), np.empty(n)
    for k in range(n):
        if k > 0:
            kf.predict(u=np.array([[flight.u[k - 1]]]))
        kf.update(np.array([[flight.z[k]]]))
        x[k], P[k], K[k] = kf.x[0, 0], kf.P[0, 0], kf.K[0, 0]
    return OneNumberTrial(sigma_q=sigma_q, sigma_r=sigma_r, x0=x0, sigma0=sigma0, flight=flight, x=x, P=P, K=K)
