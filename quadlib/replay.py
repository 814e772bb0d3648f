"""Replay a multi-rate sensor log through a filter: the one loop that drives every quadlib filter.

The timeline: inputs ``u[k]`` are given at times ``t[k]`` and hold over ``[t[k], t[k+1])``. The
filter starts at ``t[0]``; at each later ``t[k]`` it predicts over ``t[k] - t[k-1]`` with
``u[k-1]``, then applies every sensor sample whose timestamp falls in ``(t[k-1], t[k]]`` (samples
at ``t[0]`` are applied before the first predict). A sample is thus applied at the first
prediction time at or after its timestamp — at most one input period late; simulate sensors on
the input grid to avoid even that. Times are compared to within the precision they were given in
(a float32 log is not pushed a step late by its rounding).

Bad data is handled, and counted, rather than fatal:

* a missing sample is a row of NaN (in ``z`` or in its context): it is skipped (a dropout);
* a row of NaN in ``u`` holds the previous input (zero-order hold) and is flagged in the result;
* a sample whose timestamp repeats the one before it is dropped (it would be fused twice);
* with ``gate_probability`` set, each of a sensor's measurement groups is gated on its own NIS
  (sensors with ``gated=False`` excepted);
  a group rejected for longer than the sensor's ``reset_after_s`` is reset (its covariance is
  widened to the discrepancy, :meth:`~quadlib.model_filter.ModelFilter.inflate_toward`) and used
  again — a gate that would otherwise lock the sensor out for good.

Every argument is checked before the filter is touched, so a bad log leaves it unchanged. The
readable loop is a :class:`~quadlib.stepper.FilterStepper` stepped over the log: a closed loop steps
one itself, as its samples arrive, and gets the same steps.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from quadlib.engine import runner
from quadlib.model import Model
from quadlib.model_filter import ModelFilter
from quadlib.runs import FilterDivergedError, FilterRun, SensorTrace, first_steps
from quadlib.samples import Measurements, time_resolution
from quadlib.stepper import FilterStepper
from quadlib.validation import as_float_array, as_probability, as_times

__all__ = ["FilterDivergedError", "FilterRun", "SensorTrace", "rts_smooth", "run_filter"]


def held_inputs(model, u, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Inputs with NaN rows replaced by the previous row, and which rows were."""
    if u is None or model.dim_u == 0:
        return model.check_inputs(u, n), np.zeros(n, bool)
    arr = np.array(as_float_array("u", u))  # a copy: held rows are filled in
    if arr.ndim == 1 and model.dim_u == 1:
        arr = arr.reshape(-1, 1)
    if arr.shape != (n, model.dim_u):
        raise ValueError(f"u: expected shape ({n}, {model.dim_u}), got {arr.shape}")
    if np.isinf(arr).any():
        raise ValueError(f"u: expected finite inputs or NaN rows for missing ones, got inf at row "
                         f"{int(np.argmax(np.isinf(arr).any(axis=1)))}")
    held = np.isnan(arr).any(axis=1)
    if held[:-1].any():  # the last row is never used
        if held[0]:
            raise ValueError("u: expected a finite first input to hold over later NaN rows, got NaN in row 0")
        rows = np.where(held, 0, np.arange(n))
        arr = arr[np.maximum.accumulate(rows)]
    held[-1] = False
    return arr, held


def sample_steps(t: np.ndarray, grid_resolution: float, m: Measurements) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where :func:`run_filter` applies each sample of ``m`` on the input times ``t`` (given to
    ``grid_resolution``): its step index (the first ``t[k]`` at or after its time, to within the
    times' precision), whether it is missing, and whether it repeats the time before it (dropped)."""
    tol = max(grid_resolution, m.time_resolution_s)
    duplicate = np.r_[False, np.diff(m.t) <= tol]
    return np.searchsorted(t, m.t - tol, side="left"), m.missing & ~duplicate, duplicate


ENGINES = ("auto", "compiled", "readable")


def _as_engine(engine) -> str:
    if not isinstance(engine, str) or engine not in ENGINES:
        raise ValueError(f"engine: expected one of {ENGINES}, got {engine!r}")
    return engine


def run_filter(filt, t, u, measurements, gate_probability: float | None = None, engine: str = "auto") -> FilterRun:
    """Run ``filt`` over a log: predict at every input time, update at every sample.

    Parameters
    ----------
    filt : LinearKF, ModelEKF or ModelUKF
        Initialised filter; it is advanced in place.
    t : (N,) array_like
        Strictly increasing input times [s]; ``t[0]`` is the time of the initial state.
    u : (N, m) array_like, or None when the model has no input
        Inputs; ``u[k]`` holds over ``[t[k], t[k+1])`` (the last row is unused). A NaN row holds
        the previous input.
    measurements : sequence of Measurements
        One entry per sensor, applied in the given order when they share a step.
    gate_probability : float in (0, 1), optional
        χ² gate on the NIS of each of a sensor's groups (see ``update_sensor``), with the timed
        reset of each sensor's ``reset_after_s``.
    engine : {"auto", "compiled", "readable"}
        ``"auto"`` runs the same steps on the compiled engine (:mod:`quadlib.engine`) when it can —
        a :class:`~quadlib.ModelEKF` or :class:`~quadlib.ModelUKF` whose model and sensors hold
        only compiled kernels — and this
        loop otherwise; ``run.engine`` says which ran, ``run.engine_note`` why not the engine.
        ``"compiled"`` raises ``ValueError`` when the engine cannot run the filter; ``"readable"``
        always runs this loop.

    Returns
    -------
    FilterRun
    """
    if not isinstance(filt, ModelFilter):
        raise TypeError(f"filt: expected a LinearKF, ModelEKF or ModelUKF, got {type(filt).__name__}")
    engine = _as_engine(engine)
    grid_resolution = time_resolution(t)
    t = as_times("t", t)
    N = t.shape[0]
    model = filt.model
    u, held = held_inputs(model, u, N)
    if gate_probability is not None:
        gate_probability = as_probability("gate_probability", gate_probability)
    try:
        measurements = list(measurements)
    except TypeError as err:
        raise TypeError(f"measurements: expected a sequence of Measurements, got {measurements!r}") from err
    for i, m in enumerate(measurements):
        if not isinstance(m, Measurements):
            raise TypeError(f"measurements[{i}]: expected Measurements, got {type(m).__name__}")
        filt.check_sensor(m.sensor, f"measurements[{i}].sensor")
        tol = max(grid_resolution, m.time_resolution_s)
        if m.t.size and (m.t[0] < t[0] - tol or m.t[-1] > t[-1] + tol):
            raise ValueError(
                f"measurements[{i}] ({m.sensor.name!r}).t: expected times within "
                f"[{t[0]:.6g}, {t[-1]:.6g}] s, got [{m.t[0]:.6g}, {m.t[-1]:.6g}] s"
            )
    names = [m.sensor.name for m in measurements]
    if len(set(names)) != len(names):
        raise ValueError(f"measurements: expected one entry per sensor name, got {names}")
    per_sensor = [sample_steps(t, grid_resolution, m) for m in measurements]

    note, planned = "", None
    if engine != "readable":
        planned = runner.plan(filt, measurements, gate_probability)
        if isinstance(planned, str):
            if engine == "compiled":
                raise ValueError(f"engine: expected a filter the compiled engine can run, got one it cannot: {planned}")
            note, planned = planned, None
    compiled = runner.forward(filt, planned, t, u, measurements, per_sensor) if planned else None
    if isinstance(compiled, str):
        if engine == "compiled" and compiled.startswith("numba"):
            raise ValueError(f"engine: expected a filter the compiled engine can run, got one it cannot: {compiled}")
        note, compiled = compiled, None
    if note:
        runner.warn_once(model, note)
    if compiled:
        xs, Ps, traces = compiled
        sensors = {m.sensor.name: SensorTrace(t=m.t, missing=miss, duplicate=dup, **tr)
                   for m, tr, (_, miss, dup) in zip(measurements, traces, per_sensor, strict=True)}
        run = FilterRun(t=t, x=xs, P=Ps, sensors=sensors, held_input=held, engine="compiled")
    else:
        run = replace(_run_readable(filt, t, u, held, measurements, per_sensor, gate_probability, grid_resolution),
                      t=t, engine_note=note)
    xs, Ps = run.x, run.P
    bad = ~np.isfinite(xs).all(axis=1) | ~np.isfinite(Ps).all(axis=(1, 2))
    if bad.any():
        k = int(np.argmax(bad))
        raise FilterDivergedError(
            f"run_filter: the state or covariance became non-finite at t[{k}] = {t[k]:.6g} s; "
            "check the model, Q, R and the inputs (the error's .run holds the estimates before it)",
            index=k, run=first_steps(run, k))
    return run


def _run_readable(filt, t, u, held, measurements, per_sensor, gate_probability, grid_resolution) -> FilterRun:
    """The loop itself: a :class:`~quadlib.stepper.FilterStepper` stepped over the log, given each
    step's samples (missing and repeated ones too) and the inputs as logged (NaN rows again)."""
    stepper = FilterStepper(filt, [m.sensor for m in measurements], gate_probability,
                            [max(grid_resolution, m.time_resolution_s) for m in measurements])
    by_step = [[] for _ in range(t.shape[0])]
    for i, (m, (steps, _, _)) in enumerate(zip(measurements, per_sensor, strict=True)):
        context = [None] * m.t.size if m.context is None else m.context
        for k, t_j, z, c in zip(steps.tolist(), m.t.tolist(), m.z, context, strict=True):
            by_step[k].append((i, t_j, z, c))
    rows = list(np.where(held[:, None], np.nan, u))
    for k, t_k in enumerate(t.tolist()):
        stepper.advance(t_k, rows[k - 1] if k else None, by_step[k])
    return stepper.run()


def rts_smooth(model: Model, run: FilterRun, u, engine: str = "auto") -> FilterRun:
    r"""The Rauch–Tung–Striebel backward pass over a forward run: each estimate also uses the
    samples after it.

    The forward run kept the posteriors ``x_k, P_k``; the prior of the next step is recomputed
    from the model, ``x⁻ = g(x_k, u_k, Δt)``, ``P⁻ = F P_k Fᵀ + Q`` (``F = G(x_k, u_k, Δt)``, ``Q``
    with the model's input noise). Backwards from the last step, with the gain
    ``C_k = P_k Fᵀ (P⁻)⁻¹``:

    .. math:: \delta_k = C_k\,(x^s_{k+1} \boxminus x^-), \quad x^s_k = x_k \boxplus \delta_k, \quad
              P^s_k = P_k + C_k (P^s_{k+1} - P^-) C_k^T

    For an additive model ⊞ and ⊟ are + and −; for an error-state model they are the model's
    ``state_add`` and ``residual_x``, so the correction is carried in the error coordinates the
    covariances are written in (the error at ``k`` is defined about the forward estimate ``x_k``).

    Parameters
    ----------
    model : Model
        The model the forward run used (with ``G``).
    run : FilterRun
        The forward run, from :func:`run_filter`.
    u : (N, m) array_like, or None when the model has no input
        The inputs the forward run was given (NaN rows held as there).
    engine : {"auto", "compiled", "readable"}
        As in :func:`run_filter`: the backward pass on the compiled engine when the model holds
        only compiled kernels (``"auto"``), always (``"compiled"``, else ``ValueError``) or never.

    Returns
    -------
    FilterRun
        ``x`` and ``P`` smoothed; the sensor traces are the forward run's. ``engine`` is
        ``"compiled"`` when both passes ran on the engine.
    """
    if not isinstance(model, Model):
        raise TypeError(f"model: expected a Model, got {type(model).__name__}")
    if model.G is None:
        raise ValueError(f"model: expected a model with a Jacobian G for the backward pass, got {model.name!r} without")
    if not isinstance(run, FilterRun):
        raise TypeError(f"run: expected a FilterRun from run_filter, got {type(run).__name__}")
    engine = _as_engine(engine)
    N = run.t.shape[0]
    if run.x.shape[1:] != (model.dim_x,) or run.P.shape[1:] != (model.dim_P, model.dim_P):
        raise ValueError(f"run: expected states of {model.dim_x} and covariances of {model.dim_P}² for model "
                         f"{model.name!r}, got {run.x.shape[1:]} and {run.P.shape[1:]}")
    u, _ = held_inputs(model, u, N)
    compiled = engine != "readable" and _rts_compiled(model, run, u, engine)
    if isinstance(compiled, FilterRun):
        return compiled
    add = model.state_add if model.is_error_state else np.add
    diff = model.residual_x if model.is_error_state else np.subtract
    xs, Ps = run.x.copy(), run.P.copy()
    for k in range(N - 2, -1, -1):
        dt = float(run.t[k + 1] - run.t[k])
        x, P, uk = run.x[k], run.P[k], u[k] if model.dim_u else None
        F = np.asarray(model.G(x, uk, dt), dtype=float)
        prior_P = F @ P @ F.T + model.Q(dt)
        extra = None if model.input_noise is None else model.input_noise(uk, dt)
        if extra is not None:
            prior_P = prior_P + extra
        C = np.linalg.solve(prior_P, F @ P).T  # P Fᵀ (P⁻)⁻¹, P⁻ symmetric
        x_s = add(x, C @ diff(xs[k + 1], np.asarray(model.g(x, uk, dt), dtype=float)))
        xs[k] = x_s if model.normalize is None else model.normalize(x_s)
        P_s = P + C @ (Ps[k + 1] - prior_P) @ C.T
        Ps[k] = 0.5 * (P_s + P_s.T)
    return FilterRun(t=run.t, x=xs, P=Ps, sensors=run.sensors, held_input=run.held_input,
                     engine_note=compiled or run.engine_note, layout=run.layout)


def _rts_compiled(model: Model, run: FilterRun, u: np.ndarray, engine: str) -> FilterRun | str:
    """:func:`rts_smooth`'s pass on the compiled engine, or why it cannot run there."""
    loop = runner.smoother(model)
    smoothed = loop if isinstance(loop, str) else runner.backward(loop, run.t, u, run.x, run.P)
    if isinstance(smoothed, str):
        if engine == "compiled" and (loop is smoothed or smoothed.startswith("numba")):
            raise ValueError(f"engine: expected a model the compiled engine can run, got one it cannot: {smoothed}")
        runner.warn_once(model, smoothed)
        return smoothed
    return FilterRun(t=run.t, x=smoothed[0], P=smoothed[1], sensors=run.sensors, held_input=run.held_input,
                     engine=run.engine, engine_note=run.engine_note, layout=run.layout)
