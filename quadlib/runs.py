"""What a filter run returns: each step's estimate (:class:`FilterRun`) and what each sensor's
samples did (:class:`SensorTrace`), as :func:`~quadlib.replay.run_filter` and
:class:`~quadlib.stepper.FilterStepper` give them, and the error a run that became non-finite raises."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["FilterDivergedError", "FilterRun", "SensorTrace", "first_steps"]


@dataclass(frozen=True)
class SensorTrace:
    """What the filter did with each sample of one sensor.

    Attributes
    ----------
    t : (K,) sample times [s]
    innovation : (K, k) innovations; NaN where the sample was not applied
    S : (K, k, k) innovation covariances; NaN where not applied
    nis : (K,) normalised innovation squared; NaN where not applied
    used : (K,) bool, the sample (or at least one of its groups) updated the state
    rejected : (K,) bool, the gate rejected the sample or one of its groups
    reset : (K,) bool, the sample ended a lock-out: the covariance was widened and it was used
    missing : (K,) bool, the sample or its context was NaN
    duplicate : (K,) bool, the sample repeated the previous timestamp and was dropped
    """

    t: np.ndarray
    innovation: np.ndarray
    S: np.ndarray
    nis: np.ndarray
    used: np.ndarray
    rejected: np.ndarray
    reset: np.ndarray
    missing: np.ndarray
    duplicate: np.ndarray


@dataclass(frozen=True)
class FilterRun:
    """Result of :func:`~quadlib.replay.run_filter` (and of :meth:`~quadlib.stepper.FilterStepper.run`).

    Attributes
    ----------
    t : (N,) times [s]
    x : (N, n) posterior means at ``t``
    P : (N, p, p) posterior covariances at ``t`` (over the error state for an error-state model)
    sensors : dict of sensor name -> SensorTrace
    held_input : (N,) bool, ``u[k]`` was NaN and the previous input was used instead
    engine : ``"compiled"`` when the compiled engine ran it (:mod:`quadlib.engine`), else ``"readable"``
    engine_note : why the readable loop ran when the engine was allowed to ("" otherwise)
    layout : dict of part name -> slice (or column index) of ``x``, which the estimator attaches
        (``estimate_orientation``: ``q``, ``gyro_bias``); each part is then an attribute, ``run.q`` is
        ``run.x[:, layout["q"]]``. Empty for a bare :func:`~quadlib.replay.run_filter`.
    """

    t: np.ndarray
    x: np.ndarray
    P: np.ndarray
    sensors: dict
    held_input: np.ndarray
    engine: str = "readable"
    engine_note: str = ""
    layout: dict = field(default_factory=dict)

    def __post_init__(self):
        if not isinstance(self.layout, dict):
            raise TypeError(f"layout: expected a dict of part name -> slice, got {type(self.layout).__name__}")
        for name, columns in self.layout.items():
            if not isinstance(name, str) or not name.isidentifier() or hasattr(type(self), name):
                raise ValueError(f"layout: expected part names that are new attribute names, got {name!r}")
            if not isinstance(columns, (slice, int)) or isinstance(columns, bool):
                raise TypeError(f"layout[{name!r}]: expected a slice or a column index, got {columns!r}")

    def __getattr__(self, name: str) -> np.ndarray:
        # called only when ``name`` is not a field: a part of the state, by the layout
        layout = self.__dict__.get("layout", {})
        if name not in layout:
            raise AttributeError(f"FilterRun has no attribute or state part {name!r} (parts: {sorted(layout)})")
        return self.x[:, layout[name]]

    @property
    def sigma(self) -> np.ndarray:
        """(N, p) standard deviations, the square roots of the diagonal of ``P``."""
        return np.sqrt(np.clip(np.diagonal(self.P, axis1=1, axis2=2), 0.0, None))


class FilterDivergedError(FloatingPointError):
    """The estimate became non-finite at step ``index``; ``run`` holds the steps before it."""

    def __init__(self, message: str, index: int, run: FilterRun):
        super().__init__(message)
        self.index, self.run = index, run


def first_steps(run: FilterRun, k: int) -> FilterRun:
    """The first ``k`` steps of ``run``, with the sensor samples taken until then."""
    traces = {}
    for name, tr in run.sensors.items():
        keep = tr.t < run.t[k] if k < run.t.size else np.ones(tr.t.size, bool)
        traces[name] = SensorTrace(**{f: getattr(tr, f)[keep] for f in SensorTrace.__dataclass_fields__})
    return FilterRun(t=run.t[:k], x=run.x[:k], P=run.P[:k], sensors=traces, held_input=run.held_input[:k],
                     engine=run.engine, engine_note=run.engine_note, layout=run.layout)
