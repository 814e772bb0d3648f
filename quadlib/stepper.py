"""A filter stepped one input time at a time: the body of :func:`~quadlib.replay.run_filter`'s
readable loop, for the loops that need each estimate before the next input exists (a closed loop).

``run_filter`` hands its whole log to a :class:`FilterStepper`, step by step; a closed loop steps one
itself as its samples arrive. Both get the same steps. :meth:`FilterStepper.step` to ``t`` predicts
over ``t`` minus the previous step's time with ``u``, the input held since then (a NaN ``u`` holds
the input before it), then applies the samples it is given, sensor by sensor in the stepper's
order, each sensor's by time: a sample whose time repeats its sensor's previous one is dropped
(a duplicate); one with a NaN (in ``z`` or its context), or a frozen one (``sensor.stuck_samples``
equal readings in a row), is skipped (missing); with ``gate_probability`` each of a sensor's
groups is gated on its own NIS (sensors with ``gated=False`` excepted), and a group rejected
for longer than the sensor's ``reset_after_s`` is reset and used again. The first step only sets
the time of the filter's state and applies the samples taken then.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from quadlib.engine.numerics import lockout_cleared, lockout_expired
from quadlib.model import Sensor
from quadlib.model_filter import ModelFilter, agreement_test, group_gates
from quadlib.runs import FilterDivergedError, FilterRun, SensorTrace, first_steps
from quadlib.samples import Measurements
from quadlib.validation import as_finite_number, as_float_array, as_positive, as_probability

__all__ = ["FilterStepper", "Sample"]


class Sample(NamedTuple):
    """One sample of the sensor named ``sensor``: ``z`` taken at ``t`` [s], with its ``context`` for
    a sensor with ``context_names``. A NaN in ``z`` or the context marks it missing."""

    sensor: str
    t: float
    z: object
    context: object = None


def _row(name: str, value) -> np.ndarray:
    """``value`` as a float copy (the stepper keeps it for its log), a number as one element."""
    arr = np.array(as_float_array(name, value), dtype=float)
    return arr.reshape(1) if arr.ndim == 0 else arr


def _has_nan(a: np.ndarray) -> bool:
    return any(v != v for v in a.tolist())  # for a short row, quicker than np.isnan(a).any()


class _Log:
    """One sensor's samples and what the filter did with each."""

    def __init__(self, sensor: Sensor, tol: float, gates, agreement):
        self.sensor, self.tol, self.gates = sensor, tol, gates
        n = len(sensor.groups)
        self.locked_since = np.full(n, np.nan)  # per group: since when the gate rejects it (NaN: it does not)
        self.agreement = agreement  # (W, z) of agreement_test, when a reset needs the refused readings to agree
        self.refused = np.zeros((n, sensor.dim_z + 2))  # per group: its lock-out's (add_refused)
        self.rejected, self.expired = np.zeros(n, np.bool_), np.zeros(n, np.bool_)
        self.locked = False  # whether any group is locked out (else a passed sample has nothing to end)
        self.row_group = np.empty(sensor.dim_z, np.int64)
        for g, rows in enumerate(sensor.groups):
            self.row_group[list(rows)] = g
        self.last_t, self.last_z, self.equal_run = None, None, 0  # the duplicate and stuck rules
        self.rows = []  # per sample: (t, z, context, innovation or None, missing, duplicate)

    def lockout(self, t_j: float, inn) -> tuple[int, ...]:
        """The groups of ``inn`` the gate refused whose lock-out has lasted the sensor's
        ``reset_after_s`` by ``t_j`` (and whose refused readings agree, when that is asked): the
        engine's bookkeeping, :func:`~quadlib.engine.numerics.lockout_expired`."""
        self.rejected[:] = False
        self.rejected[list(inn.rejected_groups)] = True
        W, z = self.agreement if self.agreement is not None else (None, np.nan)
        whitened = W @ inn.y if W is not None else np.zeros(self.sensor.dim_z)
        lockout_expired(self.rejected, self.locked_since, self.refused, t_j, float(self.sensor.reset_after_s), z,
                        whitened, self.row_group, self.expired)
        self.locked = True
        return tuple(np.flatnonzero(self.expired).tolist())

    def lockout_ends(self, inn) -> None:
        """End the lock-out of every group ``inn`` did not reject (:func:`~quadlib.engine.numerics.lockout_cleared`)."""
        if not self.locked:
            return
        self.rejected[:] = False
        self.rejected[list(inn.rejected_groups)] = True
        lockout_cleared(self.rejected, self.locked_since, self.refused)
        self.locked = not np.isnan(self.locked_since).all()

    def screen(self, t_j: float, z: np.ndarray, c) -> tuple[bool, bool]:
        """``(missing, duplicate)`` of the next sample, in the order the sensor took them."""
        duplicate = self.last_t is not None and t_j - self.last_t <= self.tol
        self.last_t = t_j
        bad = _has_nan(z) or (c is not None and _has_nan(c))
        stuck = False
        if not bad and self.sensor.stuck_samples is not None:
            same = self.last_z is not None and bool((z == self.last_z).all())
            self.equal_run = self.equal_run + 1 if same else 0
            self.last_z = z
            stuck = self.equal_run >= self.sensor.stuck_samples - 1
        return (bad or stuck) and not duplicate, duplicate

    def trace(self) -> SensorTrace:
        k, rows = self.sensor.dim_z, self.rows
        K = len(rows)
        innovation, S, nis = np.full((K, k), np.nan), np.full((K, k, k), np.nan), np.full(K, np.nan)
        used, rejected, reset = np.zeros(K, bool), np.zeros(K, bool), np.zeros(K, bool)
        applied = [j for j, r in enumerate(rows) if r[3] is not None]
        if applied:
            inns = [rows[j][3] for j in applied]
            innovation[applied] = np.array([i.y for i in inns]).reshape(-1, k)
            S[applied] = np.array([i.S for i in inns]).reshape(-1, k, k)
            nis[applied] = [i.nis for i in inns]
            used[applied] = [i.accepted for i in inns]
            rejected[applied] = [bool(i.rejected_groups) for i in inns]
            reset[applied] = [i.reset for i in inns]
        return SensorTrace(t=np.array([r[0] for r in rows], float), innovation=innovation, S=S, nis=nis, used=used,
                           rejected=rejected, reset=reset, missing=np.array([r[4] for r in rows], bool),
                           duplicate=np.array([r[5] for r in rows], bool))

    def measurements(self) -> Measurements:
        K, sensor = len(self.rows), self.sensor
        context = None if not sensor.dim_c else np.array([r[2] for r in self.rows]).reshape(K, sensor.dim_c)
        return Measurements(sensor, np.array([r[0] for r in self.rows], float),
                            np.array([r[1] for r in self.rows]).reshape(K, sensor.dim_z), context)


class FilterStepper:
    """Step ``filt`` one input time at a time, as :func:`~quadlib.replay.run_filter` does over a log.

    Parameters
    ----------
    filt : LinearKF, ModelEKF or ModelUKF
        Initialised filter; it is advanced in place.
    sensors : sequence of Sensor
        The sensors whose samples :meth:`step` will be given, with distinct names; applied in this
        order when they share a step.
    gate_probability : float in (0, 1), optional
        χ² gate on the NIS of each of a sensor's groups, with the timed reset of its ``reset_after_s``.
    time_resolution_s : float or sequence of float (one per sensor)
        The precision of the times [s]: a sample this close to its sensor's previous one is a
        duplicate, and one this far past a step's time still belongs to it.

    Examples
    --------
    >>> stepper = FilterStepper(filt, [gps])          # doctest: +SKIP
    >>> stepper.step(0.0)                             # doctest: +SKIP
    >>> x, P = stepper.step(0.01, u, [Sample("gps", 0.01, z)])  # doctest: +SKIP
    >>> run = stepper.run()                           # doctest: +SKIP
    """

    def __init__(self, filt, sensors, gate_probability: float | None = None, time_resolution_s=1e-9):
        if not isinstance(filt, ModelFilter):
            raise TypeError(f"filt: expected a LinearKF, ModelEKF or ModelUKF, got {type(filt).__name__}")
        if isinstance(sensors, (str, bytes, Sensor)) or not hasattr(sensors, "__iter__"):
            raise TypeError(f"sensors: expected a sequence of Sensor, got {sensors!r:.60}")
        sensors = [filt.check_sensor(s, f"sensors[{i}]") for i, s in enumerate(sensors)]
        names = [s.name for s in sensors]
        if len(set(names)) != len(names):
            raise ValueError(f"sensors: expected distinct names, got {names}")
        if gate_probability is not None:
            gate_probability = as_probability("gate_probability", gate_probability)
        tols = np.atleast_1d(as_float_array("time_resolution_s", time_resolution_s))
        if tols.ndim != 1 or tols.size not in (1, len(sensors)):
            raise ValueError(f"time_resolution_s: expected a number or one per sensor ({len(sensors)}), "
                             f"got shape {np.shape(time_resolution_s)}")
        tols = np.broadcast_to(tols, (len(sensors),))
        tols = [as_positive("time_resolution_s", float(v)) for v in tols]
        self.filt, self.model = filt, filt.model
        self.start = (filt.estimate, filt.P.copy())  # the state a replay of the log starts from
        gated = [gate_probability is not None and s.gated for s in sensors]
        self._logs = [_Log(s, tol, group_gates(s, gate_probability) if g else None,
                           agreement_test(s, gate_probability) if g and s.reset_needs_agreement else None)
                      for s, tol, g in zip(sensors, tols, gated, strict=True)]
        self._index = {name: i for i, name in enumerate(names)}
        self._t, self._x, self._P, self._u, self._held = [], [], [], [], []

    # the checked entry point -------------------------------------------------------------

    def step(self, t, u=None, samples=()) -> tuple[np.ndarray, np.ndarray]:
        """Advance to time ``t`` [s] and apply ``samples``; return the estimate ``(x, P)`` there (copies).

        ``u`` is the input held since the previous step (None at the first step and for a model
        without inputs; a row of NaN holds the one before). ``samples``: a sequence of
        :class:`Sample`, each taken after the previous step's time and at the latest ``t``.
        Raises :class:`FilterDivergedError` if the estimate becomes non-finite.
        """
        t = as_finite_number("t", t)
        if self._t and t <= self._t[-1]:
            raise ValueError(f"t: expected a time after the previous step's {self._t[-1]:.9g} s, got {t:.9g} s")
        u = self._check_input(u)
        batch = self._check_samples(t, samples)
        self.advance(t, u, batch)
        x, P = self.filt.state_view(), self.filt.P
        if not (np.isfinite(x).all() and np.isfinite(P).all()):
            k = len(self._t) - 1
            raise FilterDivergedError(
                f"FilterStepper.step: the state or covariance became non-finite at t = {t:.6g} s; check the "
                "model, Q, R and the inputs (the error's .run holds the steps before)",
                index=k, run=first_steps(self.run(), k))
        return x.copy(), P.copy()

    def _check_input(self, u) -> np.ndarray | None:
        if not self._t:
            if u is not None:
                raise ValueError(f"u: expected None at the first step (the filter starts there), got {u!r:.60}")
            return None
        m = self.model.dim_u
        if u is None:
            return self.model.check_input(None)
        arr = _row("u", u)
        if arr.shape != (m,) or np.isinf(arr).any():
            raise ValueError(f"u: expected a finite input of shape ({m},) or NaN to hold the previous one, "
                             f"got {np.shape(u)} {arr!r:.60}")
        if np.isnan(arr).any() and len(self._u) == 0:
            raise ValueError("u: expected a finite first input to hold over later NaN ones, got NaN")
        return arr

    def _check_samples(self, t: float, samples) -> list:
        if isinstance(samples, (str, bytes, Sample)) or not hasattr(samples, "__iter__"):
            raise TypeError(f"samples: expected a sequence of Sample, got {samples!r:.60}")
        batch = []
        for n, s in enumerate(samples):
            where = f"samples[{n}]"
            if not isinstance(s, Sample):
                raise TypeError(f"{where}: expected a Sample(sensor, t, z, context), got {s!r:.60}")
            if s.sensor not in self._index:
                raise ValueError(f"{where}.sensor: expected one of {list(self._index)}, got {s.sensor!r}")
            i = self._index[s.sensor]
            log = self._logs[i]
            t_j = as_finite_number(f"{where}.t", s.t)
            self._check_sample_time(f"{where}.t", t_j, t, log.tol)
            z = _row(f"{where}.z", s.z)
            if z.shape != (log.sensor.dim_z,) or np.isinf(z).any():
                raise ValueError(f"{where}.z: expected {log.sensor.dim_z} finite values (or NaN for missing) of "
                                 f"{s.sensor!r}, got {s.z!r:.60}")
            c = None
            if log.sensor.dim_c or s.context is not None:
                c = None if s.context is None or not log.sensor.dim_c else _row(f"{where}.context", s.context)
                if c is None or c.shape != (log.sensor.dim_c,) or np.isinf(c).any():
                    raise ValueError(f"{where}.context: expected {log.sensor.dim_c or 'no'} values (finite or NaN) "
                                     f"for {s.sensor!r}'s context_names {log.sensor.context_names}, got "
                                     f"{s.context!r:.60}")
            batch.append((i, t_j, z, c))
        batch.sort(key=lambda e: (e[0], e[1]))  # by sensor, then time (stable: a repeat stays after)
        return batch

    def _check_sample_time(self, name: str, t_j: float, t: float, tol: float) -> None:
        """A sample is applied at the first step at or after its time, to within ``tol``; the first
        step takes the samples at its own time."""
        if self._t and not self._t[-1] < t_j - tol <= t:
            raise ValueError(f"{name}: expected a time after the previous step's {self._t[-1]:.9g} s and at the "
                             f"latest the step's {t:.9g} s, got {t_j:.9g} s")
        if not self._t and abs(t_j - t) > tol:
            raise ValueError(f"{name}: expected the first step's time {t:.9g} s, got {t_j:.9g} s")

    # the unchecked step (run_filter checked its whole log) -------------------------------

    def advance(self, t: float, u, batch) -> None:
        """:meth:`step` without argument checks: ``batch`` holds ``(sensor index, t, z, context)``,
        ordered by sensor, then time."""
        filt = self.filt
        if self._t:
            held = u is not None and _has_nan(u)
            if held:
                u = self._u[-1]
            elif u is None:
                u = np.zeros(0)
            self._u.append(u)
            self._held.append(held)
            filt.predict_unchecked(u, t - self._t[-1])
        for i, t_j, z, c in batch:
            self._apply(self._logs[i], t_j, z, c)
        self._t.append(t)
        self._x.append(filt.state_view().copy())
        self._P.append(filt.P.copy())

    def _apply(self, log: _Log, t_j: float, z: np.ndarray, c) -> None:
        """One sample: dropped, skipped or used, with the gate and the timed reset of its groups."""
        missing, duplicate = log.screen(t_j, z, c)
        if missing or duplicate:
            log.rows.append((t_j, z, c, None, missing, duplicate))
            return
        filt, sensor, gates = self.filt, log.sensor, log.gates
        inn = filt.update_unchecked(sensor, z, gates, c)
        if inn.rejected_groups and sensor.reset_after_s is not None:
            expired = log.lockout(t_j, inn)
            if expired:  # undo the partial update, widen P along the locked-out groups, use them
                filt.undo_last_update()
                filt.inflate_toward(sensor, z, expired, c)
                inn = filt.update_unchecked(sensor, z, gates, c, force=expired)._replace(reset=True)
                log.locked_since[list(expired)], log.refused[list(expired)] = np.nan, 0.0
        if gates is not None:
            log.lockout_ends(inn)
        log.rows.append((t_j, z, c, inn, False, False))

    # results -----------------------------------------------------------------------------

    def run(self) -> FilterRun:
        """The steps so far as a :class:`FilterRun` (``held_input[k]``: the input given at step
        ``k + 1``, the one held from ``t[k]``, was NaN)."""
        N = len(self._t)
        held = np.zeros(N, bool)
        held[:N - 1] = self._held
        return FilterRun(t=np.array(self._t, float), x=np.array(self._x).reshape(N, self.model.dim_x),
                         P=np.array(self._P).reshape(N, self.model.dim_P, self.model.dim_P),
                         sensors={log.sensor.name: log.trace() for log in self._logs}, held_input=held)

    def log(self) -> tuple[np.ndarray, np.ndarray | None, list[Measurements]]:
        """``(t, u, measurements)``: the steps as a log for :func:`~quadlib.replay.run_filter`, which
        replays them to the same estimates (``u[k]`` is the input given at step ``k + 1``, NaN rows
        as given; the last row, never used, is zero; None for a model without inputs)."""
        N, m = len(self._t), self.model.dim_u
        u = None
        if m:
            u = np.zeros((N, m))
            u[:N - 1] = np.array(self._u).reshape(N - 1, m)
            u[:N - 1][np.array(self._held, bool)] = np.nan
        return np.array(self._t, float), u, [log.measurements() for log in self._logs]
