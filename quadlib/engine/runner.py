"""Between :func:`~quadlib.replay.run_filter` and the compiled loops: which filters the engine can
run, and their arrays.

:func:`plan` looks at a filter and its sensors: a :class:`~quadlib.ModelEKF` whose model and
sensors hold only :class:`~quadlib.engine.kernel.Kernel` functions the engine knows
(:data:`~quadlib.engine.dispatch.TABLES`) is packed into the engine's records; anything else — a
function written in plain Python, a model changed with ``dataclasses.replace`` to one, another
kind of filter — gets the reason it must run on the readable loop, which ``run_filter`` records in
the run. :func:`forward` and :func:`backward` call the loops of :mod:`quadlib.engine.ekf`.
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints

from quadlib.engine.dispatch import kind_of
from quadlib.engine.ekf import ModelArrays, Samples, SensorArrays, SigmaArrays, rts_pass
from quadlib.engine.kernel import MODEL_ROLES, Kernel
from quadlib.engine.loop import filter_pass
from quadlib.filters import ModelEKF, ModelUKF, sigma_point_sqrt
from quadlib.model import Model
from quadlib.model_filter import agreement_test, group_gates

__all__ = ["backward", "forward", "model_arrays", "plan"]

_REQUIRED = ("g", "G", "Q")
_UNUSED_BY_UKF = ("G", "add_jacobian")


def _kernel(owner: str, role: str, f) -> tuple[int, np.ndarray] | str:
    """``f``'s number and parameters, or why the engine cannot call it."""
    if not isinstance(f, Kernel):
        return f"{owner}'s {role} is plain Python ({getattr(f, '__name__', type(f).__name__)})"
    kind = kind_of(f)
    if kind < 0 or f.role != role:
        return f"{owner}'s {role} is {f!r}, which the engine does not know"
    return kind, f.params


def _padded(rows: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
    width = max([1] + [r.size for r in rows])
    out = np.zeros(shape + (width,))
    for index, r in enumerate(rows):
        out.reshape(-1, width)[index, :r.size] = r
    return out


def model_arrays(model: Model, unscented: bool = False) -> ModelArrays | str:
    """The engine's record of ``model`` (for a UKF when ``unscented``: without ``G``), or why it has none."""
    if not isinstance(model, Model):
        return f"the model is a {type(model).__name__}"
    kinds, params = np.full(len(MODEL_ROLES), -1, np.int64), []
    for r, role in enumerate(MODEL_ROLES):
        f = getattr(model, role)
        if (f is None and role not in _REQUIRED) or (unscented and role in _UNUSED_BY_UKF):
            params.append(np.zeros(0))
            continue
        found = _kernel(f"model {model.name!r}", role, f)
        if isinstance(found, str):
            return found
        kinds[r] = found[0]
        params.append(found[1])
    return ModelArrays(kinds, _padded(params, (len(MODEL_ROLES),)), model.is_error_state)


def _sigma_arrays(filt: ModelUKF) -> SigmaArrays | str:
    """The engine's record of ``filt``'s sigma points, or why it has none."""
    points = filt.points_fn
    if type(points) is not MerweScaledSigmaPoints or points.sqrt is not sigma_point_sqrt:
        return f"the UKF's sigma points are {type(points).__name__} of its own; the engine draws ModelUKF's default"
    if filt.state_add is not np.add:
        return "the UKF's state_add is its own; the engine adds a correction"
    if points.subtract is not filt.residual_x:
        return "the UKF's sigma points subtract with another function than its residual_x"
    kinds, params = np.full(2, -1, np.int64), []
    for r, (role, f) in enumerate((("residual_x", filt.residual_x), ("mean", filt.x_mean))):
        if f is np.subtract or f is None:
            params.append(np.zeros(0))
            continue
        found = _kernel("the UKF", role, f)
        if isinstance(found, str):
            return found
        kinds[r] = found[0]
        params.append(found[1])
    lam = points.alpha**2 * (points.n + points.kappa) - points.n
    return SigmaArrays(np.array(filt.Wm, np.float64), np.array(filt.Wc, np.float64), float(lam + points.n), kinds,
                       _padded(params, (2,)))


def plan(filt, measurements: list, gate_probability: float | None) -> tuple[ModelArrays, SensorArrays,
                                                                              SigmaArrays | None] | str:
    """The engine's records of ``filt`` (advanced from its current state), the sensors of
    ``measurements``, gated at ``gate_probability``, and a UKF's sigma points; or why it must run on
    the readable loop."""
    if type(filt) not in (ModelEKF, ModelUKF):
        return f"the filter is a {type(filt).__name__}; the engine runs ModelEKF and ModelUKF"
    unscented = type(filt) is ModelUKF
    sigma = _sigma_arrays(filt) if unscented else None
    if isinstance(sigma, str):
        return sigma
    model = model_arrays(filt.model, unscented)
    if isinstance(model, str):
        return model
    sensors = [m.sensor for m in measurements]
    kinds, params = np.full((len(sensors), 4), -1, np.int64), []
    for i, s in enumerate(sensors):
        for r, role in enumerate(("h", "H", "residual", "mean")):
            f = getattr(s, role)
            if (role == "residual" and f is np.subtract) or (role == "mean" and (f is None or not unscented)) or (
                    role == "H" and unscented):
                params.append(np.zeros(0))
                continue
            found = _kernel(f"sensor {s.name!r}", role, f)
            if isinstance(found, str):
                return found
            kinds[i, r] = found[0]
            params.append(found[1])
    n, k, g = len(sensors), max([1] + [s.dim_z for s in sensors]), max([1] + [len(s.groups) for s in sensors])
    R, group, gates = np.zeros((n, k, k)), np.zeros((n, k), np.int64), np.zeros((n, g))
    corrected = np.ones((n, filt.model.dim_P), np.bool_)
    whiten, agree_z = np.zeros((n, k, k)), np.full(n, np.nan)
    for i, s in enumerate(sensors):
        R[i, :s.dim_z, :s.dim_z] = s.R
        for number, rows in enumerate(s.groups):
            group[i, list(rows)] = number
        if gate_probability is not None and s.gated:
            gates[i, :len(s.groups)] = group_gates(s, gate_probability)
            if s.reset_needs_agreement:
                whiten[i, :s.dim_z, :s.dim_z], agree_z[i] = agreement_test(s, gate_probability)
        corrected[i, list(s.uncorrected)] = False
    return model, SensorArrays(
        kinds=kinds, params=_padded(params, (n, 4)), dim_z=np.array([s.dim_z for s in sensors], np.int64),
        dim_c=np.array([s.dim_c for s in sensors], np.int64), R=R, group=group,
        n_groups=np.array([len(s.groups) for s in sensors], np.int64), gates=gates,
        reset_after_s=np.array([s.reset_after_s or 0.0 for s in sensors]), corrected=corrected, whiten=whiten,
        agree_z=agree_z), sigma


def _samples(measurements: list, per_sensor: list, k: int) -> Samples:
    """The sensors' samples padded into one record, with the ones each applies and their steps."""
    n, K = len(measurements), max([1] + [m.t.size for m in measurements])
    t, z = np.zeros((n, K)), np.zeros((n, K, k))
    c = np.zeros((n, K, max([1] + [m.sensor.dim_c for m in measurements])))
    applied = [np.flatnonzero(~missing & ~duplicate) for _, missing, duplicate in per_sensor]
    use = np.zeros((n, max([1] + [a.size for a in applied])), np.int64)
    step = np.zeros_like(use)
    for i, (m, (steps, _, _), a) in enumerate(zip(measurements, per_sensor, applied, strict=True)):
        t[i, :m.t.size], z[i, :m.t.size, :m.sensor.dim_z] = m.t, m.z
        if m.sensor.dim_c:
            c[i, :m.t.size, :m.sensor.dim_c] = m.context
        use[i, :a.size], step[i, :a.size] = a, steps[a]
    return Samples(t, z, c, use, step, np.array([a.size for a in applied], np.int64))


def forward(filt: ModelEKF | ModelUKF, records: tuple[ModelArrays, SensorArrays, SigmaArrays | None], t: np.ndarray,
            u: np.ndarray,
            measurements: list, per_sensor: list) -> tuple | None:
    """The forward pass from ``filt``'s state over times ``t`` with held inputs ``u``, each sensor's
    samples scheduled by :func:`~quadlib.replay.sample_steps` (``per_sensor``). Returns ``x``, ``P``
    and each sensor's trace (innovation, ``S``, NIS, used, rejected, reset), and advances ``filt``
    to the end; None if the pass raised or became non-finite (``filt`` unchanged: the readable loop
    then runs and says where)."""
    model, sensors, sigma = records
    q_dt, Q = filt.reused_noise
    try:
        with np.errstate(all="ignore"):
            xs, Ps, q_dt, Q, *traces = filter_pass(
                np.require(t, np.float64, "CW"), np.require(u, np.float64, "CW"),
                np.array(filt.state_view(), np.float64), np.array(filt.P, np.float64), float(q_dt),
                np.array(Q, np.float64), model, sensors, _samples(measurements, per_sensor, sensors.R.shape[1]), sigma)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return None
    if not (np.isfinite(xs).all() and np.isfinite(Ps).all()):
        return None
    filt.continue_from(xs[-1], Ps[-1], (q_dt, Q))
    ys, Ss, nis, used, rejected, reset = traces
    out = []
    for i, m in enumerate(measurements):
        K, k = m.t.size, m.sensor.dim_z
        out.append(dict(innovation=ys[i, :K, :k], S=Ss[i, :K, :k, :k], nis=nis[i, :K], used=used[i, :K],
                        rejected=rejected[i, :K], reset=reset[i, :K]))
    return xs, Ps, out


def backward(records: ModelArrays, t: np.ndarray, u: np.ndarray, xs: np.ndarray, Ps: np.ndarray) -> tuple | None:
    """The RTS backward pass of :func:`~quadlib.replay.rts_smooth` on the engine: ``(x, P)``
    smoothed, or None if it raised (the readable pass then runs)."""
    try:
        with np.errstate(all="ignore"):
            return rts_pass(np.require(t, np.float64, "CW"), np.require(u, np.float64, "CW"),
                            np.require(xs, np.float64, "CW"), np.require(Ps, np.float64, "CW"), records)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return None
