"""Interactive tuning: what the chapters' sliders compute, and the sliders.

Each ``*_trial`` function runs one small, seeded experiment for one setting and returns a
record with a one-line ``summary()`` and, if it has a figure, a ``draw(fig)`` that draws on a
matplotlib ``Figure`` it is given; :func:`plot_trial` makes that figure and :func:`show_trial`
prints and shows it — the callback of a slider. A chapter offers the sliders
(:func:`tuning_sliders`, live only in Jupyter) and then calls :func:`show_trial` once with fixed
values, an output that the tests check and the book shows. A chapter's own experiment becomes a
slider the same way: any record with ``summary()`` (and ``draw(fig)``) will do.

The figures are ``matplotlib.figure.Figure`` objects made directly, never through pyplot: in
JupyterLab a widget's callback may run on another thread than the cell that drew before it, and
pyplot's current figure is shared between threads, so a callback that used it could draw on the
wrong figure and show a blank one.

* :func:`kf_tuning_trial` — the 1D quadrotor's Kalman filter with an assumed σ_w (Q) and σ_r (R)
  over simulated flights: RMSE, and mean NEES / NIS against their χ² bands (chapters 06, 08).
* :func:`complementary_trial` — the complementary filter's roll and pitch with a time constant
  τ on the square flights of chapter 10.
* :func:`gate_trial` — a χ² gate of a chosen probability on the 2D quadrotor's sonar with
  dropouts and outliers: outliers caught, good samples lost, RMSE (chapter 09).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from quadlib.analysis.metrics import chi2_interval, rmse
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.attitude.complementary import nonlinear_complementary
from quadlib.filters import LinearKF, ModelEKF
from quadlib.model_filter import gate_threshold
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.quad1d import climb_input, quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
from quadlib.sim.imu import imu_samples
from quadlib.sim.simulate import with_dropouts, with_outage, with_outliers
from quadlib.teaching.bands import consistency_verdict
from quadlib.validation import as_bool, as_count, as_positive, as_probability

__all__ = ["LABELS", "ComplementaryTrial", "GateTrial", "KfTuningTrial", "complementary_trial", "gate_trial",
           "kf_tuning_trial", "plot_trial", "show_trial", "tuning_sliders"]

KF_TRUE_SIGMAS = (0.3, 0.1)  # the 1D quadrotor's true σ_w [m/s²] and σ_r [m] (chapters 06 and 08)


@dataclass(frozen=True)
class KfTuningTrial:
    """The 1D quadrotor's KF with assumed ``sigma_w`` and ``sigma_r`` over ``n_flights`` flights:
    the mean NEES at each time ``t`` and NIS at each range sample ``t_range``, their 95 % χ²
    ``nees_band`` and ``nis_band`` for that many flights, and the height RMSE after the first
    second, ``rmse_z`` [m]."""

    sigma_w: float
    sigma_r: float
    n_flights: int
    t: np.ndarray
    mean_nees: np.ndarray
    t_range: np.ndarray
    mean_nis: np.ndarray
    nees_band: tuple[float, float]
    nis_band: tuple[float, float]
    rmse_z: float

    @property
    def anees(self) -> float:
        """The NEES averaged over flights and time."""
        return float(self.mean_nees.mean())

    @property
    def anis(self) -> float:
        """The NIS averaged over flights and range samples."""
        return float(np.nanmean(self.mean_nis))

    @property
    def verdict(self) -> str:
        """:func:`~quadlib.teaching.bands.consistency_verdict` of :attr:`anees` and ``nees_band``."""
        return consistency_verdict(self.anees, self.nees_band)

    def summary(self) -> str:
        return (f"assumed σ_w = {self.sigma_w:.3g} m/s², σ_r = {self.sigma_r:.3g} m over {self.n_flights} flights: "
                f"height RMSE {100 * self.rmse_z:.1f} cm; mean NEES {self.anees:.2f} (band {self.nees_band[0]:.2f}"
                f"–{self.nees_band[1]:.2f}), mean NIS {self.anis:.2f} (band {self.nis_band[0]:.2f}–"
                f"{self.nis_band[1]:.2f}): {self.verdict}")

    def draw(self, fig) -> None:
        """Mean NEES and NIS against their χ² bands (:func:`~quadlib.teaching.bands.plot_chi2_band`:
        shaded bands, plain log ticks where the values span decades), side by side on ``fig``, with
        one legend above them."""
        from quadlib.teaching.bands import plot_chi2_band

        axes = fig.subplots(1, 2)
        plot_chi2_band(self.t, self.mean_nees, 2, n_runs=self.n_flights, ax=axes[0], name="NEES",
                       label="mean NEES or NIS")
        plot_chi2_band(self.t_range, self.mean_nis, 1, n_runs=self.n_flights, ax=axes[1], name="NIS", marker=".")
        axes[0].set_title("NEES (n = 2)", fontsize="medium")
        axes[1].set_title("NIS of the range sensor", fontsize="medium")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside upper center", ncol=3, fontsize="small", frameon=False)


def kf_tuning_trial(sigma_w: float, sigma_r: float, n_flights: int = 20, seed: int = 0,
                    true_sigma_w: float = KF_TRUE_SIGMAS[0]) -> KfTuningTrial:
    """Run the 1D quadrotor's KF assuming ``sigma_w`` [m/s²] and ``sigma_r`` [m] on ``n_flights``
    10 s flights (Δt = 0.02 s, 10 Hz range, the climb profile of chapters 06 and 08) simulated with
    ``true_sigma_w`` and the true σ_r = 0.1 m, all starting from the filter's prior."""
    sigma_w, sigma_r = as_positive("sigma_w", sigma_w), as_positive("sigma_r", sigma_r)
    true_sigma_w = as_positive("true_sigma_w", true_sigma_w)
    n_flights, rng = as_count("n_flights", n_flights, 2), np.random.default_rng(as_count("seed", seed, 0))
    dt = 0.02
    t = np.arange(0.0, 10.0 + dt / 2, dt)
    u = climb_input(t)
    x0, P0 = np.array([0.0, 1.0]), np.diag([0.5**2, 0.5**2])
    assumed = quad1d_model(sigma_w)
    runs = run_monte_carlo({"KF": lambda a, b: LinearKF(assumed, a, b, dt)}, quad1d_model(true_sigma_w),
                           [quad1d_range_sensor(KF_TRUE_SIGMAS[1], rate_hz=10)], x0, P0, t, u, n_flights, rng,
                           assumed_sensors={"KF": [quad1d_range_sensor(sigma_r, rate_hz=10)]})["KF"]
    nis = runs.nis["range"]
    t_range = 0.1 * np.arange(nis.shape[1])  # the range samples, every 0.1 s from t = 0
    return KfTuningTrial(sigma_w=sigma_w, sigma_r=sigma_r, n_flights=n_flights, t=t,
                         mean_nees=runs.nees.mean(axis=0), t_range=t_range, mean_nis=nis.mean(axis=0),
                         nees_band=tuple(chi2_interval(2, n_flights)), nis_band=tuple(chi2_interval(1, n_flights)),
                         rmse_z=float(rmse(runs.errors[:, t > 1.0, 1].ravel())))


@dataclass(frozen=True)
class ComplementaryTrial:
    """The complementary filter with time constant ``tau`` [s] on one square ``flight`` ("slow" or
    "fast", optionally with a gyro bias): times ``t``, true and estimated roll and pitch
    ``truth``, ``estimate`` (N × 2, rad), and the RMS errors ``rms_deg`` (roll, pitch)."""

    tau: float
    flight: str
    gyro_bias: bool
    t: np.ndarray
    truth: np.ndarray
    estimate: np.ndarray

    @property
    def rms_deg(self) -> np.ndarray:
        return np.degrees(np.sqrt(np.mean((self.estimate - self.truth) ** 2, axis=0)))

    def summary(self) -> str:
        roll, pitch = self.rms_deg
        bias = ", gyro biased by 0.02 rad/s" if self.gyro_bias else ""
        return f"τ = {self.tau:.3g} s on the {self.flight} square{bias}: RMS error roll {roll:.2f}°, pitch {pitch:.2f}°"

    def draw(self, fig) -> None:
        """Roll and pitch against the truth, side by side on ``fig``, one legend above them."""
        axes = fig.subplots(1, 2, sharey=True)
        for ax, i, name in zip(axes, (0, 1), ("roll", "pitch"), strict=True):
            ax.plot(self.t, np.degrees(self.truth[:, i]), "k", lw=1, label="truth")
            ax.plot(self.t, np.degrees(self.estimate[:, i]), "C0", lw=1, label=f"estimate, τ = {self.tau:.3g} s")
            ax.set_xlabel("t [s]")
            ax.set_ylabel(f"{name} [deg]")
        bias = ", gyro biased" if self.gyro_bias else ""
        fig.suptitle(f"The complementary filter's roll and pitch on the {self.flight} square{bias}", fontsize="medium")
        handles, labels = axes[0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="outside upper right", ncol=2, fontsize="small", frameon=False)


FLIGHTS = {"slow": dict(leg_s=8.0, turn_s=2.0), "fast": dict(leg_s=3.0, turn_s=2.0)}  # chapter 10's squares


def complementary_trial(tau: float, flight: str = "fast", gyro_bias: bool = False, seed: int = 0) -> ComplementaryTrial:
    """Run :func:`~quadlib.attitude.complementary.nonlinear_complementary` with ``tau`` [s] on
    chapter 10's ``flight`` square, sampled at 500 Hz with :class:`~quadlib.quad.flight.SensorNoise3D`
    (and a gyro bias of 0.02 rad/s on each axis when ``gyro_bias``); the yaw is the true one."""
    tau = as_positive("tau", tau)
    if flight not in FLIGHTS:
        raise ValueError(f"flight: expected one of {sorted(FLIGHTS)}, got {flight!r}")
    gyro_bias = as_bool("gyro_bias", gyro_bias)
    fl = square_course(**FLIGHTS[flight])
    noise = SensorNoise3D(gyro_bias_rad_s=(0.02, 0.02, 0.02)) if gyro_bias else SensorNoise3D()
    log = imu_samples(fl, noise, np.random.default_rng(as_count("seed", seed, 0)))
    estimate = nonlinear_complementary(fl.dt, log.gyro, log.accel, tau, yaw=fl.euler[:, 2])
    return ComplementaryTrial(tau=tau, flight=flight, gyro_bias=gyro_bias, t=fl.t, truth=fl.euler[:, :2],
                              estimate=estimate)


@dataclass(frozen=True)
class GateTrial:
    """An EKF with a χ² gate of ``gate_probability`` (None: no gate) on ``n_flights`` sonar flights
    of the 2D quadrotor with 20 % dropouts, a 1 s outage and 10 % outliers (10 × the noise):
    ``caught`` (share of outliers rejected), ``good_lost`` (share of good samples rejected), the
    RMSE of y [m] and the mean NEES."""

    gate_probability: float | None
    n_flights: int
    caught: float
    good_lost: float
    rmse_y: float
    anees: float

    def summary(self) -> str:
        gate = "no gate" if self.gate_probability is None else f"gate probability {self.gate_probability:.5g}"
        return (f"{gate}, {self.n_flights} flights: outliers caught {self.caught:.0%}, good samples rejected "
                f"{self.good_lost:.1%}, RMSE y {100 * self.rmse_y:.1f} cm, mean NEES {self.anees:.2f} (n = 3)")


def gate_trial(gate_probability: float | None, n_flights: int = 20, seed: int = 0) -> GateTrial:
    """The sonar scenario of chapter 09 (roll swing 8°, roll error 1°, σ_r = 5 cm, 5 m from the wall,
    3 s at Δt = 0.05 s, 10 Hz) through :func:`~quadlib.analysis.montecarlo.run_monte_carlo` with
    ``gate_probability``."""
    if gate_probability is not None:
        gate_probability = as_probability("gate_probability", gate_probability)
    n_flights, rng = as_count("n_flights", n_flights, 2), np.random.default_rng(as_count("seed", seed, 0))
    dt, wall, roll_error = 0.05, 5.0, np.radians(1.0)
    t = np.arange(0.0, 3.0 + dt / 2, dt)
    model, sensor = quad2d_model(0.2, roll_error), quad2d_range_sensor(0.05, wall_y_m=wall, rate_hz=10)
    u = -np.radians(8.0) * np.cos(2.5 * t)[:, None]
    x0, P0 = np.array([0.0, 0.0, 0.0]), np.diag([roll_error**2, 0.05**2, 0.1**2])
    outliers = []

    def corrupt(samples, rng_):
        bad, outlier = with_outliers(with_outage(with_dropouts(samples[0], rng_, 0.2), 1.0, 2.0), rng_, 0.1,
                                     noise_scale=10.0)
        outliers.append(outlier)
        return [bad]

    res = run_monte_carlo({"EKF": lambda a, b: ModelEKF(model, a, b, dt)}, model, [sensor], x0, P0, t, u,
                          n_flights, rng, corrupt=corrupt, gate_probability=gate_probability)["EKF"]
    outlier, nis = np.array(outliers), res.nis["range"]
    rejected = nis > gate_threshold(1, gate_probability) if gate_probability is not None else np.zeros_like(outlier)
    good = ~outlier & ~np.isnan(nis)
    return GateTrial(gate_probability=gate_probability, n_flights=n_flights,
                     caught=float(np.sum(rejected & outlier) / max(outlier.sum(), 1)),
                     good_lost=float(np.sum(rejected & good) / good.sum()),
                     rmse_y=float(rmse(res.errors[:, :, 2].ravel())), anees=float(res.nees.mean()))


def _trial(trial):
    if not callable(getattr(trial, "summary", None)):
        raise TypeError(f"trial: expected a trial record with summary() (a KfTuningTrial, ComplementaryTrial, "
                        f"GateTrial or a chapter's own), got {type(trial).__name__}")
    return trial


def plot_trial(trial, figsize=(10.0, 3.0)):
    """A new ``matplotlib.figure.Figure`` (not pyplot's) with ``trial.draw(fig)`` on it, laid out;
    None for a trial without a figure (no ``draw``)."""
    from matplotlib.figure import Figure

    draw = getattr(_trial(trial), "draw", None)
    if draw is None:
        return None
    fig = Figure(figsize=figsize, layout="constrained")
    draw(fig)
    return fig


def show_trial(trial) -> None:
    """Print a trial's summary and show its figure (a slider's callback)."""
    from IPython.display import display

    print(_trial(trial).summary())
    fig = plot_trial(trial)
    if fig is not None:
        display(fig)


LABELS = {
    "sigma_w": "assumed σ_w [m/s²]", "true_sigma_w": "true σ_w [m/s²]", "sigma_r": "assumed σ_r [m]",
    "sigma_p": "assumed σ_p [m]", "sigma_v": "assumed σ_v [m/s]", "sigma_q": "assumed σ_q [m]",
    "x0": "first guess x₀ [m]", "sigma0": "its σ₀ [m]", "tau": "time constant τ [s]", "flight": "flight",
    "gyro_bias": "gyro bias", "gate_probability": "gate probability",
}
"""The controls' labels, by the trial functions' argument names (a name not listed is shown as it is)."""


def tuning_sliders(trial_function, **sliders):
    """Controls (ipywidgets) that rerun ``trial_function(**values)`` and show the result when one
    is released. Each control is ``(low, high)`` for a slider on a logarithmic scale, starting at the
    geometric middle; ``[False, True]`` (either order) for a checkbox; a list of up to four strings
    for toggle buttons; any other list of options for a slider over them; each starts at its first
    option. Labels come from :data:`LABELS`. In Jupyter the returned widget displays itself; outside
    a kernel it does nothing."""
    import ipywidgets as widgets

    if not callable(trial_function):
        raise TypeError(f"trial_function: expected a callable, got {type(trial_function).__name__}")
    controls = {}
    style, layout = {"description_width": "11em"}, widgets.Layout(width="34em")
    for name, spec in sliders.items():
        label = LABELS.get(name, name)
        if isinstance(spec, tuple) and len(spec) == 2 and 0.0 < spec[0] < spec[1]:
            low, high = np.log10(spec[0]), np.log10(spec[1])
            controls[name] = widgets.FloatLogSlider(value=10 ** ((low + high) / 2), base=10, min=low, max=high,
                                                    step=(high - low) / 40, description=label, readout_format=".3g",
                                                    continuous_update=False, style=style, layout=layout)
        elif isinstance(spec, list) and len(spec) == 2 and set(map(type, spec)) == {bool} and spec[0] != spec[1]:
            controls[name] = widgets.Checkbox(value=spec[0], description=label, indent=False)
        elif isinstance(spec, list) and 0 < len(spec) <= 4 and all(isinstance(o, str) for o in spec):
            controls[name] = widgets.ToggleButtons(options=spec, value=spec[0], description=label, style=style)
        elif isinstance(spec, list) and spec:
            controls[name] = widgets.SelectionSlider(options=[(str(o), o) for o in spec], index=0, description=label,
                                                     continuous_update=False, style=style, layout=layout)
        else:
            raise ValueError(f"{name}: expected (low, high) with 0 < low < high, or a non-empty list, got {spec!r}")
    if not controls:
        raise ValueError("sliders: expected at least one slider, got none")
    return widgets.interactive(lambda **values: show_trial(trial_function(**values)), **controls)
