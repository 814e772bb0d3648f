"""Descriptions of a motion model and of a sensor.

A :class:`Model` bundles the pure functions of a transition model
(Tellex et al. §3, Algorithm 2):

.. math::

    \\bar\\mu_t = g(\\mu_{t-1}, u_t, \\Delta t), \\qquad
    G_t = \\frac{\\partial g}{\\partial x}\\Big|_{\\mu_{t-1}}, \\qquad
    \\bar\\Sigma_t = G_t \\Sigma_{t-1} G_t^\\top + Q(\\Delta t)

and a :class:`Sensor` bundles a measurement model :math:`z = h(x) + v`,
:math:`v \\sim \\mathcal N(0, R)`, with its Jacobian :math:`H = \\partial h / \\partial x`.
Argument order is ``g(x, u, dt)`` everywhere (the seeds write ``g(u, x)``).
Functions take and return 1-D arrays and never modify their inputs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from quadlib.validation import as_bool, as_count, as_covariance, as_finite_array, as_optional, as_positive, as_vector

__all__ = ["Model", "Sensor"]

Array = np.ndarray


def _check_names(owner: str, field_name: str, names) -> tuple[str, ...]:
    if isinstance(names, str) or not all(isinstance(n, str) for n in names):
        raise TypeError(f"{owner}.{field_name}: expected a sequence of str, got {names!r}")
    names = tuple(names)
    if len(set(names)) != len(names):
        raise ValueError(f"{owner}.{field_name}: expected unique names, got {names}")
    return names


@dataclass(frozen=True)
class Model:
    """A discrete-time motion model ``x_k = g(x_{k-1}, u_k, dt) + w``, ``w ~ N(0, Q(dt))``.

    Parameters
    ----------
    state_names : tuple of str
        Names of the ``n`` state components, with units, e.g. ``("z [m]", "vz [m/s]")``.
    input_names : tuple of str
        Names of the ``m`` control inputs (may be empty).
    g : callable ``g(x, u, dt) -> (n,)``
        Transition function.
    Q : callable ``Q(dt) -> (p, p)``
        Process-noise covariance accumulated over one step of length ``dt``.
    G : callable ``G(x, u, dt) -> (p, p)``, optional
        Jacobian of ``g`` with respect to the state (the error state for an
        error-state model). Required by the EKF and the linear KF; the UKF
        does not use it.
    B : callable ``B(x, u, dt) -> (n, m)``, optional
        Jacobian of ``g`` with respect to ``u``. Required only by the linear
        Kalman filter, which needs ``g(x, u, dt) = G x + B u``.
    name : str
        Short human-readable name.
    normalize : callable ``normalize(x) -> (n,)``, optional
        Puts a state back on its manifold (a quaternion to unit norm, an angle
        to (−π, π]); the filters apply it after every predict and update.
    normalize_jacobian : callable ``normalize_jacobian(x) -> (n, n)``, optional
        ``∂normalize/∂x`` at ``x``. Given (additive models only), the covariance
        is carried through the normalisation too, ``P ← J P Jᵀ``: for a quaternion
        this removes the variance along the unit sphere's normal, a direction the
        measurements cannot see and that otherwise leaks into the other states.
    error_names : tuple of str, optional
        Names of the ``p`` components of an error state. Given, the model is an
        *error-state* (multiplicative) model: the filters keep the full state
        ``x`` (``n``) outside and a covariance over the error ``δx`` (``p``),
        and ``G``, ``Q`` and every sensor's ``H`` are taken with respect to
        ``δx``. Without it ``p = n`` and ``δx`` is an ordinary difference.
    state_add : callable ``state_add(x, dx) -> (n,)``, optional
        ``x ⊞ δx``: applies an error to a state (``q ⊗ exp(δθ)`` for an
        attitude). Required with ``error_names``.
    residual_x : callable ``residual_x(x1, x0) -> (p,)``, optional
        ``x1 ⊟ x0``: the error that takes ``x0`` to ``x1``, the inverse of
        ``state_add``. Required with ``error_names``.
    input_noise : callable ``input_noise(u, dt) -> (p, p) or None``, optional
        Process noise that depends on the step's input, added to ``Q(dt)``; ``None`` when the
        input adds nothing. A gyro sample at its full scale turns the attitude by an unknown
        extra angle (:func:`quadlib.imu.saturated_step_variance`).
    vectorized : bool
        True when ``g`` and ``G`` also take a stack of states ``(M, n)`` (one input ``u``, one ``dt``)
        and return one result per state, ``(M, n)`` and ``(M, p, p)``: the filters can then run many
        flights at once (:mod:`quadlib.analysis.batched`).
    add_jacobian : callable ``add_jacobian(x) -> (n, p)``, optional
        ``∂(x ⊞ δx)/∂δx`` at ``δx = 0``. Given, the sensors' ``H`` are taken with
        respect to the full state ``x`` (so one sensor serves both kinds of
        model) and the EKF chains them, ``H_δ = H(x) · add_jacobian(x)``;
        without it, an error-state model's sensors give ``H`` with respect to ``δx``.
    """

    state_names: tuple[str, ...]
    input_names: tuple[str, ...]
    g: Callable[[Array, Array, float], Array]
    Q: Callable[[float], Array]
    G: Callable[[Array, Array, float], Array] | None = None
    B: Callable[[Array, Array, float], Array] | None = None
    name: str = "model"
    normalize: Callable[[Array], Array] | None = None
    normalize_jacobian: Callable[[Array], Array] | None = None
    error_names: tuple[str, ...] | None = None
    state_add: Callable[[Array, Array], Array] | None = None
    residual_x: Callable[[Array, Array], Array] | None = None
    add_jacobian: Callable[[Array], Array] | None = None
    input_noise: Callable[[Array, float], Array | None] | None = None
    vectorized: bool = False

    def __post_init__(self):
        object.__setattr__(self, "state_names", _check_names("Model", "state_names", self.state_names))
        object.__setattr__(self, "input_names", _check_names("Model", "input_names", self.input_names))
        if not self.state_names:
            raise ValueError("Model.state_names: expected at least one state, got none")
        if self.error_names is not None:
            object.__setattr__(self, "error_names", _check_names("Model", "error_names", self.error_names))
            if self.state_add is None or self.residual_x is None:
                raise ValueError("Model.error_names: an error-state model needs state_add and residual_x, "
                                 f"got state_add={self.state_add!r}, residual_x={self.residual_x!r}")
        elif any(f is not None for f in (self.state_add, self.residual_x, self.add_jacobian)):
            raise ValueError("Model.state_add, Model.residual_x, Model.add_jacobian: expected only with error_names, "
                             "got error_names=None")
        object.__setattr__(self, "vectorized", as_bool("Model.vectorized", self.vectorized))
        if self.normalize_jacobian is not None and (self.normalize is None or self.error_names is not None):
            raise ValueError("Model.normalize_jacobian: expected only with normalize on an additive model")
        optional = ("G", "B", "normalize", "normalize_jacobian", "state_add", "residual_x", "add_jacobian",
                    "input_noise")
        for attr in ("g", "Q") + tuple(a for a in optional if getattr(self, a) is not None):
            if not callable(getattr(self, attr)):
                raise TypeError(f"Model.{attr}: expected a callable, got {type(getattr(self, attr)).__name__}")

    @property
    def dim_x(self) -> int:
        """Number of states ``n``."""
        return len(self.state_names)

    @property
    def is_error_state(self) -> bool:
        """True when the covariance is over an error state (``error_names`` given)."""
        return self.error_names is not None

    @property
    def dim_P(self) -> int:
        """Size ``p`` of the covariance: the error state's, or ``n``."""
        return len(self.error_names) if self.error_names is not None else self.dim_x

    @property
    def dim_u(self) -> int:
        """Number of inputs ``m``."""
        return len(self.input_names)

    def check_state(self, x, name: str = "x") -> Array:
        """Return ``x`` as a finite ``(n,)`` vector or raise ``ValueError``."""
        return as_vector(name, x, self.dim_x)

    def check_input(self, u, name: str = "u") -> Array:
        """Return ``u`` as a finite ``(m,)`` vector (``None`` allowed when ``m == 0``)."""
        if u is None and self.dim_u == 0:
            return np.zeros(0)
        if u is None:
            raise ValueError(f"{name}: expected shape ({self.dim_u},), got None")
        return as_vector(name, u, self.dim_u)

    def check_inputs(self, u, n_steps: int, name: str = "u") -> Array:
        """Return an input series as a finite ``(n_steps, m)`` array.

        ``None`` is accepted for a model without inputs, and a 1-D array for a
        model with one input.
        """
        if u is None:
            if self.dim_u:
                raise ValueError(f"{name}: expected shape ({n_steps}, {self.dim_u}), got None")
            return np.zeros((n_steps, 0))
        u = as_finite_array(name, u)
        if u.ndim == 1 and self.dim_u == 1:
            u = u.reshape(-1, 1)
        if u.shape != (n_steps, self.dim_u):
            raise ValueError(f"{name}: expected shape ({n_steps}, {self.dim_u}), got {u.shape}")
        return u

    def step(self, x, u, dt) -> Array:
        """Apply ``g`` once, with every argument checked."""
        return as_vector(
            "g(x, u, dt)",
            self.g(self.check_state(x), self.check_input(u), as_positive("dt", dt)),
            self.dim_x,
        )


@dataclass(frozen=True)
class Sensor:
    """A measurement model ``z = h(x) + v``, ``v ~ N(0, R)``.

    Parameters
    ----------
    name : str
        Identifier used in logs and results, e.g. ``"range"``.
    measurement_names : tuple of str
        Names of the ``k`` measured components, with units.
    h : callable ``h(x) -> (k,)``
        Expected measurement for state ``x``.
    R : (k, k) array_like
        Measurement-noise covariance (variances, not standard deviations).
    H : callable ``H(x) -> (k, n)``, optional
        Jacobian of ``h``. Required by the EKF and the linear KF; the UKF does
        not use it.
    residual : callable ``residual(z, z_hat) -> (k,)``, optional
        Innovation ``z - z_hat``; give one that wraps angles to (-pi, pi].
        The default ``np.subtract`` lets the filters take their fast path.
    mean : callable ``mean(Z, weights) -> (k,)``, optional
        Weighted mean of measurement sigma points ``Z`` of shape ``(2n+1, k)``,
        for the UKF; give one for angles. Defaults to ``weights @ Z``.
    rate_hz : float, optional
        Nominal sample rate, for documentation and simulators.
    context_names : tuple of str, optional
        Names of per-sample values that ``h`` and ``H`` need besides the state
        (the fixed-wing accelerometer needs the gyro rates and the airspeed).
        Given, they are called ``h(x, c)`` and ``H(x, c)``, and each sample
        carries its own ``c`` (see :class:`~quadlib.samples.Measurements`).
    groups : tuple of tuples of int, optional
        Components gated together, a partition of ``range(k)`` (GPS: position
        ``(0, 1, 2)`` and velocity ``(3, 4, 5)``). A gate tests each group's
        NIS on its own and updates with the groups that pass. Default: one group.
    reset_after_s : float, optional
        When a group has been rejected by the gate continuously for longer than
        this [s], :func:`~quadlib.replay.run_filter` inflates the covariance
        along that group's directions by the discrepancy and accepts it again
        (a reset). ``None``: never (a gate can then lock the sensor out for good).
    stuck_samples : int, optional
        A sample equal to the ``n − 1`` present samples before it is a frozen sensor's and is
        skipped like a missing one (:func:`~quadlib.samples.stuck_rows`). ``None``: never. Use it
        only for sensors whose noise makes exact repeats impossible.
    uncorrected : tuple of int, optional
        Indices of (error-)state components this sensor's update leaves unchanged: their rows
        of the gain are zero (a "consider" or Schmidt update), and the Joseph form keeps the
        covariance exact for that gain. A magnetometer that should correct the heading but
        never the gyro bias. Supported by :class:`~quadlib.ModelEKF`.
    gated : bool
        False: :func:`~quadlib.replay.run_filter`'s χ² gate never tests this sensor. For a
        measurement that cannot jump — an average over seconds — the gate can only refuse it
        after the estimate has drifted away, which is when it is needed most.
    vectorized : bool
        True when ``h`` and ``H`` also take a stack of states ``(M, n)`` and return one result per
        state, ``(M, k)`` (or ``(M,)`` when ``k = 1``) and ``(M, k, n)``
        (:mod:`quadlib.analysis.batched`).
    reset_needs_agreement : bool
        With ``reset_after_s``: a lock-out ends only once the readings the gate refused agree with
        one another, their scatter about their own mean (whitened by ``R``) within the χ² bound at
        the gate's probability (:func:`~quadlib.model_filter.agreement_test`). Readings that agree
        and still miss the estimate say the estimate is off, and it is reset to them; readings that
        scatter more than ``R`` allows (a magnet that turns with the sensor) stay refused.
    """

    name: str
    measurement_names: tuple[str, ...]
    h: Callable[[Array], Array]
    R: Array
    H: Callable[[Array], Array] | None = None
    residual: Callable[[Array, Array], Array] = np.subtract
    mean: Callable[[Array, Array], Array] | None = None
    rate_hz: float | None = field(default=None)
    context_names: tuple[str, ...] = ()
    groups: tuple[tuple[int, ...], ...] = ()
    reset_after_s: float | None = None
    stuck_samples: int | None = None
    uncorrected: tuple[int, ...] = ()
    gated: bool = True
    vectorized: bool = False
    reset_needs_agreement: bool = False

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise (ValueError if isinstance(self.name, str) else TypeError)(
                f"Sensor.name: expected a non-empty str, got {self.name!r}")
        names = _check_names(f"Sensor({self.name!r})", "measurement_names", self.measurement_names)
        object.__setattr__(self, "measurement_names", names)
        if not names:
            raise ValueError(f"Sensor({self.name!r}).measurement_names: expected at least one, got none")
        R = as_covariance(f"Sensor({self.name!r}).R", self.R, len(names))
        R.setflags(write=False)
        object.__setattr__(self, "R", R)
        if self.rate_hz is not None:
            object.__setattr__(self, "rate_hz", as_positive(f"Sensor({self.name!r}).rate_hz", self.rate_hz))
        if self.context_names:
            ctx = _check_names(f"Sensor({self.name!r})", "context_names", self.context_names)
            object.__setattr__(self, "context_names", ctx)
        groups = tuple(tuple(int(i) for i in g) for g in self.groups) or (tuple(range(len(names))),)
        if sorted(i for g in groups for i in g) != list(range(len(names))) or any(not g for g in groups):
            raise ValueError(f"Sensor({self.name!r}).groups: expected a partition of range({len(names)}), "
                             f"got {self.groups!r}")
        object.__setattr__(self, "groups", groups)
        if self.reset_after_s is not None:
            object.__setattr__(self, "reset_after_s",
                               as_positive(f"Sensor({self.name!r}).reset_after_s", self.reset_after_s))
        object.__setattr__(self, "stuck_samples", as_optional(
            as_count, f"Sensor({self.name!r}).stuck_samples", self.stuck_samples, low=2))
        try:
            uncorrected = tuple(self.uncorrected)
        except TypeError:
            uncorrected = None
        if uncorrected is not None:
            uncorrected = tuple(as_count(f"Sensor({self.name!r}).uncorrected[{j}]", i, low=0)
                                for j, i in enumerate(uncorrected))
        if uncorrected is None or len(set(uncorrected)) != len(uncorrected):
            raise ValueError(f"Sensor({self.name!r}).uncorrected: expected distinct state indices >= 0, "
                             f"got {self.uncorrected!r}")
        object.__setattr__(self, "uncorrected", uncorrected)
        for flag in ("gated", "vectorized", "reset_needs_agreement"):
            object.__setattr__(self, flag, as_bool(f"Sensor({self.name!r}).{flag}", getattr(self, flag)))
        if self.reset_needs_agreement:
            if self.reset_after_s is None:
                raise ValueError(f"Sensor({self.name!r}).reset_needs_agreement: expected False without "
                                 "reset_after_s (there is no reset to condition), got True")
            smallest = np.linalg.eigvalsh(self.R).min()
            if smallest <= 0.0:
                raise ValueError(f"Sensor({self.name!r}).R: expected a positive definite covariance with "
                                 "reset_needs_agreement (the refused readings are whitened by it), got smallest "
                                 f"eigenvalue {smallest:.3g}")
        for attr in ("h", "residual") + tuple(a for a in ("H", "mean") if getattr(self, a) is not None):
            if not callable(getattr(self, attr)):
                raise TypeError(f"Sensor({self.name!r}).{attr}: expected a callable, got {getattr(self, attr)!r}")

    @property
    def dim_z(self) -> int:
        """Number of measured components ``k``."""
        return len(self.measurement_names)

    @property
    def dim_c(self) -> int:
        """Number of per-sample context values (0 for an ordinary sensor)."""
        return len(self.context_names)

    def check_context(self, c, name: str = "context") -> Array | None:
        """Return ``c`` as a finite ``(dim_c,)`` vector, or None for a sensor without context."""
        if not self.dim_c:
            if c is not None:
                raise ValueError(f"{name} ({self.name}): expected None (the sensor has no context_names), got {c!r}")
            return None
        return as_vector(f"{name} ({self.name})", c, self.dim_c)

    def subset(self, rows) -> Sensor:
        """The same sensor measuring only components ``rows``: for updating with the groups a gate passed.

        ``residual`` and ``mean`` are applied to the full vector with the other components set to
        zero, so they must act component by component (as wrapping an angle does).
        """
        rows = np.asarray(rows, dtype=int)
        k = self.dim_z

        def embed(v):
            full = np.zeros(v.shape[:-1] + (k,))
            full[..., rows] = v
            return full

        has_c = bool(self.dim_c)
        h = (lambda x, c: self.h(x, c)[rows]) if has_c else (lambda x: self.h(x)[rows])
        H = None
        if self.H is not None:
            H = (lambda x, c: np.asarray(self.H(x, c))[rows]) if has_c else (lambda x: np.asarray(self.H(x))[rows])
        mean = None if self.mean is None else (lambda Z, w: self.mean(embed(Z), w)[rows])
        residual = np.subtract if self.residual is np.subtract else (
            lambda a, b: np.asarray(self.residual(embed(a), embed(b)))[rows])
        return Sensor(name=self.name, measurement_names=tuple(self.measurement_names[i] for i in rows), h=h, H=H,
                      R=self.R[np.ix_(rows, rows)], residual=residual, mean=mean, context_names=self.context_names,
                      uncorrected=self.uncorrected)

    def check_measurement(self, z, name: str = "z") -> Array:
        """Return ``z`` as a finite ``(k,)`` vector or raise ``ValueError``."""
        return as_vector(f"{name} ({self.name})", z, self.dim_z)
