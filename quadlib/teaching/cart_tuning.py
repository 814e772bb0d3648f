"""The Q and R slider of chapter 06: the cart's Kalman filter with assumed noises, over many runs.

The cart of :mod:`quadlib.teaching.cart` is pushed, coasts, brakes and stops
(:func:`cart_push_input`) for 30 s; a filter at Δt = 0.1 s fuses a position sensor at 1 Hz and a
wheel odometer at 5 Hz. The truth has an unmodelled acceleration of σ_w = 0.2 m/s², a position
noise of σ_p = 0.5 m and a speed noise of σ_v = 0.1 m/s (``CART_TRUE_SIGMAS``).
:func:`cart_tuning_trial` runs the filter with the σ's it is *told* on simulated runs and returns a
:class:`CartTuningTrial`: the position and speed RMSE, the mean NEES and the mean NIS of each sensor
against their χ² bands, and a figure (``draw(fig)``) of the three.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.analysis.metrics import chi2_interval, rmse
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.filters import LinearKF
from quadlib.sim.trajectories import piecewise_constant
from quadlib.teaching.bands import consistency_verdict
from quadlib.teaching.cart import cart_model, cart_position_sensor, cart_speed_sensor
from quadlib.validation import as_count, as_positive, as_times

__all__ = ["CART_TRUE_SIGMAS", "CartTuningTrial", "cart_push_input", "cart_tuning_trial"]

CART_TRUE_SIGMAS = (0.2, 0.5, 0.1)  # σ_w [m/s²], σ_p [m], σ_v [m/s] of the simulated cart
CART_DT_S, CART_DURATION_S, CART_RATES_HZ = 0.1, 30.0, (1.0, 5.0)  # filter step, run length, sensor rates
CART_PRIOR = (np.array([0.0, 0.0]), np.diag([0.5**2, 2.0**2]))  # x0 = [v, p], P0


def cart_push_input(t) -> np.ndarray:
    """The cart's commanded acceleration ``(N, 1)`` [m/s²] at times ``t`` [s]: pushed at +0.5 m/s²
    for 4 s (to 2 m/s), coasting, braked at −0.4 m/s² from 14 s to 19 s (to rest), then at rest."""
    return piecewise_constant(as_times("t", t), [0.0, 4.0, 14.0, 19.0], [0.5, 0.0, -0.4, 0.0])[:, None]


@dataclass(frozen=True)
class CartTuningTrial:
    """The cart's KF told ``sigma_w``, ``sigma_p`` and ``sigma_v`` over ``n_flights`` runs: the mean
    NEES at each time ``t``, the mean NIS at each position sample ``t_position`` and speed sample
    ``t_speed``, their 95 % χ² bands for that many runs, and the RMSE of position [m] and speed
    [m/s] after the first 2 s."""

    sigma_w: float
    sigma_p: float
    sigma_v: float
    n_flights: int
    t: np.ndarray
    mean_nees: np.ndarray
    t_position: np.ndarray
    mean_nis_position: np.ndarray
    t_speed: np.ndarray
    mean_nis_speed: np.ndarray
    nees_band: tuple[float, float]
    nis_band: tuple[float, float]
    rmse_p: float
    rmse_v: float

    @property
    def anees(self) -> float:
        """The NEES averaged over runs and time."""
        return float(self.mean_nees.mean())

    @property
    def anis_position(self) -> float:
        """The position sensor's NIS averaged over runs and samples."""
        return float(np.nanmean(self.mean_nis_position))

    @property
    def anis_speed(self) -> float:
        """The odometer's NIS averaged over runs and samples."""
        return float(np.nanmean(self.mean_nis_speed))

    @property
    def verdict(self) -> str:
        """:func:`~quadlib.teaching.bands.consistency_verdict` of :attr:`anees` and ``nees_band``."""
        return consistency_verdict(self.anees, self.nees_band)

    def summary(self) -> str:
        return (f"told σ_w = {self.sigma_w:.3g} m/s², σ_p = {self.sigma_p:.3g} m, σ_v = {self.sigma_v:.3g} m/s, "
                f"{self.n_flights} runs: RMSE {100 * self.rmse_p:.1f} cm, {100 * self.rmse_v:.1f} cm/s; "
                f"mean NEES {self.anees:.2f} (band {self.nees_band[0]:.2f}–{self.nees_band[1]:.2f}), "
                f"mean NIS position {self.anis_position:.2f}, speed {self.anis_speed:.2f} "
                f"(band {self.nis_band[0]:.2f}–{self.nis_band[1]:.2f}): {self.verdict}")

    def draw(self, fig) -> None:
        """Mean NEES, position NIS and speed NIS against their χ² bands, side by side on ``fig``,
        with one legend above them."""
        from quadlib.teaching.bands import plot_chi2_band

        axes = fig.subplots(1, 3)
        plot_chi2_band(self.t, self.mean_nees, 2, n_runs=self.n_flights, ax=axes[0], name="NEES",
                       label="mean NEES or NIS")
        plot_chi2_band(self.t_position, self.mean_nis_position, 1, n_runs=self.n_flights, ax=axes[1],
                       name="NIS", marker=".")
        plot_chi2_band(self.t_speed, self.mean_nis_speed, 1, n_runs=self.n_flights, ax=axes[2], name="NIS",
                       marker=".")
        for ax, title in zip(axes, ("NEES (n = 2)", "NIS of the position sensor", "NIS of the odometer"),
                             strict=True):
            ax.set_title(title, fontsize="medium")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside upper center", ncol=3, fontsize="small", frameon=False)


def cart_tuning_trial(sigma_w: float, sigma_p: float, sigma_v: float = CART_TRUE_SIGMAS[2], n_flights: int = 20,
                      seed: int = 0) -> CartTuningTrial:
    """Run the cart's KF told ``sigma_w`` [m/s²] (its Q), ``sigma_p`` [m] and ``sigma_v`` [m/s] (its
    two R's) on ``n_flights`` simulated 30 s runs of the truth ``CART_TRUE_SIGMAS``, every run
    starting from the filter's prior (module documentation)."""
    sigma_w, sigma_p = as_positive("sigma_w", sigma_w), as_positive("sigma_p", sigma_p)
    sigma_v = as_positive("sigma_v", sigma_v)
    n_flights, rng = as_count("n_flights", n_flights, 2), np.random.default_rng(as_count("seed", seed, 0))
    t = np.arange(0.0, CART_DURATION_S + CART_DT_S / 2, CART_DT_S)
    u = cart_push_input(t)
    x0, P0 = CART_PRIOR
    true_w, true_p, true_v = CART_TRUE_SIGMAS
    rate_p, rate_v = CART_RATES_HZ
    told = cart_model(sigma_w)
    runs = run_monte_carlo({"KF": lambda a, b: LinearKF(told, a, b, CART_DT_S)}, cart_model(true_w),
                           [cart_position_sensor(true_p, rate_hz=rate_p), cart_speed_sensor(true_v, rate_hz=rate_v)],
                           x0, P0, t, u, n_flights, rng,
                           assumed_sensors={"KF": [cart_position_sensor(sigma_p, rate_hz=rate_p),
                                                   cart_speed_sensor(sigma_v, rate_hz=rate_v)]})["KF"]
    nis_p, nis_v = runs.nis["position"], runs.nis["speed"]
    late = t > 2.0
    return CartTuningTrial(sigma_w=sigma_w, sigma_p=sigma_p, sigma_v=sigma_v, n_flights=n_flights, t=t,
                           mean_nees=runs.nees.mean(axis=0),
                           t_position=np.arange(nis_p.shape[1]) / rate_p, mean_nis_position=nis_p.mean(axis=0),
                           t_speed=np.arange(nis_v.shape[1]) / rate_v, mean_nis_speed=nis_v.mean(axis=0),
                           nees_band=tuple(chi2_interval(2, n_flights)), nis_band=tuple(chi2_interval(1, n_flights)),
                           rmse_p=float(rmse(runs.errors[:, late, 1].ravel())),
                           rmse_v=float(rmse(runs.errors[:, late, 0].ravel())))
