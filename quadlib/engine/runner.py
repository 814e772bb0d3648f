"""Between :func:`~quadlib.replay.run_filter` and a filter's compiled loop: its kernels and records.

:func:`plan` looks at a filter and its sensors: a :class:`~quadlib.ModelEKF` or
:class:`~quadlib.ModelUKF` whose model and sensors hold :class:`~quadlib.engine.kernel.Kernel`
functions — quadlib's or anyone's, as long as numba compiled them — gets its loop from
:mod:`quadlib.engine.build` and its records; anything else (a function written in plain Python, a
sigma-point object of the user's own, another kind of filter) gets the reason it runs on the
readable loop, which ``run_filter`` records in the run. :func:`forward` and :func:`backward` call
the loops.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints

from quadlib.engine.build import Compiled, CompileError, filter_loops, is_compiled, smoother_loops
from quadlib.engine.kernel import MODEL_ROLES, Kernel
from quadlib.engine.records import Samples, SensorArrays, SigmaArrays
from quadlib.filters import ModelEKF, ModelUKF, sigma_point_sqrt
from quadlib.kernels.attitude import identity_jacobian
from quadlib.model import Model
from quadlib.model_filter import agreement_test, group_gates

__all__ = ["Plan", "backward", "forward", "plan", "smoother"]

_REQUIRED = ("g", "G", "Q")
_UNUSED_BY_UKF = ("G", "add_jacobian")


class Plan(NamedTuple):
    """A filter's compiled loop and what it reads: the model's parameters ``(9, m)``, the sensors'
    and a UKF's sigma points (None for an EKF)."""

    loop: Compiled
    model_params: np.ndarray
    sensors: SensorArrays
    sigma: SigmaArrays | None


def _kernel(owner: str, role: str, f):
    """``f``'s numba function, or why the engine cannot call it."""
    if not isinstance(f, Kernel):
        return f"{owner}'s {role} is plain Python ({getattr(f, '__name__', type(f).__name__)})"
    if f.role != role:
        return f"{owner}'s {role} is a Kernel for {f.role!r}"
    if not is_compiled(f.function):
        return f"{owner}'s {role} is a Kernel of {f.function!r}, which numba did not compile (use @njit)"
    return f.function


def _padded(rows: list[np.ndarray], shape: tuple[int, ...]) -> np.ndarray:
    width = max([1] + [r.size for r in rows])
    out = np.zeros(shape + (width,))
    for index, r in enumerate(rows):
        out.reshape(-1, width)[index, :r.size] = r
    return out


def _kernels(owner: str, fields) -> tuple[dict, list[np.ndarray]] | str:
    """The numba functions (role → function, None where ``used`` is False) and parameters of ``fields``,
    ``(role, f, used)`` triples of ``owner``; or why one cannot be called."""
    kernels, params = {}, []
    for role, f, used in fields:
        kernels[role], p = None, np.zeros(0)
        if used:
            found = _kernel(owner, role, f)
            if isinstance(found, str):
                return found
            kernels[role], p = found, f.params
        params.append(p)
    return kernels, params


def _model_kernels(model: Model, unscented: bool) -> tuple[dict, np.ndarray] | str:
    """``model``'s kernels (role → numba function or None) and their parameters, or why it has none."""
    if not isinstance(model, Model):
        return f"the model is a {type(model).__name__}"
    found = _kernels(f"model {model.name!r}", [
        (role, getattr(model, role), (getattr(model, role) is not None or role in _REQUIRED)
         and not (unscented and role in _UNUSED_BY_UKF)) for role in MODEL_ROLES])
    if isinstance(found, str):
        return found
    kernels, params = found
    kernels["G_identity"] = kernels["G"] is identity_jacobian  # I P Iᵀ is P: its product skipped
    return kernels, _padded(params, (len(MODEL_ROLES),))


def _sigma(filt: ModelUKF) -> tuple[dict, SigmaArrays] | str:
    """A UKF's sigma-point kernels and record, or why the engine cannot draw its points."""
    points = filt.points_fn
    if type(points) is not MerweScaledSigmaPoints or points.sqrt is not sigma_point_sqrt:
        return f"the UKF's sigma points are {type(points).__name__} of its own; the engine draws ModelUKF's default"
    if filt.state_add is not np.add:
        return "the UKF's state_add is its own; the engine adds a correction"
    if points.subtract is not filt.residual_x:
        return "the UKF's sigma points subtract with another function than its residual_x"
    found = _kernels("the UKF", [(role, f, f is not np.subtract and f is not None)
                                 for role, f in (("residual_x", filt.residual_x), ("mean", filt.x_mean))])
    if isinstance(found, str):
        return found
    kernels, params = found
    lam = points.alpha**2 * (points.n + points.kappa) - points.n
    return kernels, SigmaArrays(np.array(filt.Wm, np.float64), np.array(filt.Wc, np.float64), float(lam + points.n),
                                _padded(params, (2,)))


def _sensor_kernels(sensors: list, unscented: bool) -> tuple[list[dict], np.ndarray] | str:
    """Each sensor's kernels (role → numba function or None) and their parameters ``(S, 4, m)``."""
    kernels, params = [], []
    for s in sensors:
        found = _kernels(f"sensor {s.name!r}", [
            ("h", s.h, True), ("H", s.H, not unscented), ("residual", s.residual, s.residual is not np.subtract),
            ("mean", s.mean, unscented and s.mean is not None)])
        if isinstance(found, str):
            return found
        kernels.append(found[0])
        params += found[1]
    return kernels, _padded(params, (len(sensors), 4))


_LOOPS: dict[tuple, Compiled] = {}  # one build per filter's kernels and flags in a process
_WARNED: set[str] = set()


def _loop(build, key: tuple, *args) -> Compiled | str:
    """The compiled loop of ``key`` (built once), or why numba could not compile it."""
    if key not in _LOOPS:
        try:
            _LOOPS[key] = build(*args)
        except CompileError as err:
            return str(err)
    return _LOOPS[key]


def _frozen(kernels: dict) -> tuple:
    return tuple(sorted(kernels.items()))


def plan(filt, measurements: list, gate_probability: float | None) -> Plan | str:
    """The loop and records of ``filt`` (advanced from its current state), the sensors of
    ``measurements``, gated at ``gate_probability``; or why it must run on the readable loop."""
    if type(filt) not in (ModelEKF, ModelUKF):
        return f"the filter is a {type(filt).__name__}; the engine runs ModelEKF and ModelUKF"
    unscented = type(filt) is ModelUKF
    kind = "UKF" if unscented else "EKF"
    sigma_kernels, sigma = {}, None
    if unscented:
        found = _sigma(filt)
        if isinstance(found, str):
            return found
        sigma_kernels, sigma = found
    found = _model_kernels(filt.model, unscented)
    if isinstance(found, str):
        return found
    model_kernels, model_params = found
    sensors = [m.sensor for m in measurements]
    found = _sensor_kernels(sensors, unscented)
    if isinstance(found, str):
        return found
    sensor_kernels, sensor_params = found
    key = (kind, filt.model.is_error_state, _frozen(model_kernels), tuple(map(_frozen, sensor_kernels)),
           _frozen(sigma_kernels))
    loop = _loop(filter_loops, key, f"{filt.model.name} {kind}", kind, model_kernels, filt.model.is_error_state,
                 sensor_kernels, sigma_kernels)
    if isinstance(loop, str):
        return loop
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
    return Plan(loop, model_params, SensorArrays(
        params=sensor_params, dim_z=np.array([s.dim_z for s in sensors], np.int64),
        dim_c=np.array([s.dim_c for s in sensors], np.int64), R=R, group=group,
        n_groups=np.array([len(s.groups) for s in sensors], np.int64), gates=gates,
        reset_after_s=np.array([s.reset_after_s or 0.0 for s in sensors]), corrected=corrected, whiten=whiten,
        agree_z=agree_z), sigma)


def smoother(model: Model) -> tuple[Compiled, np.ndarray] | str:
    """The compiled RTS backward pass of ``model`` and its parameters, or why it has none."""
    found = _model_kernels(model, False)
    if isinstance(found, str):
        return found
    kernels, params = found
    loop = _loop(smoother_loops, ("RTS", model.is_error_state, _frozen(kernels)), f"{model.name} smoother", kernels,
                 model.is_error_state)
    return loop if isinstance(loop, str) else (loop, params)


def warn_once(model: Model, reason: str) -> None:
    """Say once per model and reason that a filter whose kernels numba could not compile runs on
    the readable loop (a model of plain Python functions runs there without a word: that is its choice)."""
    if not reason.startswith("numba could not compile"):
        return
    key = f"{model.name}: {reason}"
    if key not in _WARNED:
        _WARNED.add(key)
        warnings.warn(f"model {model.name!r} runs on the readable loop: {reason}", RuntimeWarning,
                      stacklevel=3)


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


def forward(filt: ModelEKF | ModelUKF, planned: Plan, t: np.ndarray, u: np.ndarray, measurements: list,
            per_sensor: list) -> tuple | str:
    """The forward pass from ``filt``'s state over times ``t`` with held inputs ``u``, each sensor's
    samples scheduled by :func:`~quadlib.replay.sample_steps` (``per_sensor``). Returns ``x``, ``P``
    and each sensor's trace (innovation, ``S``, NIS, used, rejected, reset), and advances ``filt``
    to the end; or why it did not (numba could not compile the loop, or the pass raised or became
    non-finite: ``filt`` is unchanged and the readable loop then runs and says where)."""
    filt.fold_error()
    q_dt, Q = filt.reused_noise
    try:
        with np.errstate(all="ignore"):
            xs, Ps, q_dt, Q, *traces = planned.loop(
                np.require(t, np.float64, "CW"), np.require(u, np.float64, "CW"),
                np.array(filt.state_view(), np.float64), np.array(filt.P, np.float64), float(q_dt),
                np.array(Q, np.float64), filt.fixed_Q, planned.model_params, planned.sensors,
                _samples(measurements, per_sensor, planned.sensors.R.shape[1]), planned.sigma)
    except CompileError as err:
        return str(err)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return "the compiled run raised, so the readable loop ran (and names the step where it fails)"
    if not (np.isfinite(xs).all() and np.isfinite(Ps).all()):
        return "the compiled run became non-finite, so the readable loop ran (and names the step where it fails)"
    filt.continue_from(xs[-1], Ps[-1], (q_dt, Q))
    ys, Ss, nis, used, rejected, reset = traces
    out = []
    for i, m in enumerate(measurements):
        K, k = m.t.size, m.sensor.dim_z
        out.append(dict(innovation=ys[i, :K, :k], S=Ss[i, :K, :k, :k], nis=nis[i, :K], used=used[i, :K],
                        rejected=rejected[i, :K], reset=reset[i, :K]))
    return xs, Ps, out


def backward(loop: tuple[Compiled, np.ndarray], t: np.ndarray, u: np.ndarray, xs: np.ndarray,
             Ps: np.ndarray) -> tuple | str:
    """The RTS backward pass of :func:`~quadlib.replay.rts_smooth` on the engine: ``(x, P)``
    smoothed, or why not (the readable pass then runs)."""
    compiled, params = loop
    try:
        with np.errstate(all="ignore"):
            return compiled(np.require(t, np.float64, "CW"), np.require(u, np.float64, "CW"),
                            np.require(xs, np.float64, "CW"), np.require(Ps, np.float64, "CW"), params)
    except CompileError as err:
        return str(err)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return "the compiled backward pass raised, so the readable one ran"

