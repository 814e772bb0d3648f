"""What every quadlib filter shares: the predict/update interface, the χ² gate, error-state folding.

:class:`ModelFilter` is mixed in before a filterpy filter class (see :mod:`quadlib.filters`). It
checks arguments at the boundary, reuses ``Q(dt)`` while ``dt`` does not change, gates updates on
the NIS, applies the model's ``normalize`` hook, and — for an error-state model — keeps the full
state outside filterpy and folds each error into it.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from scipy.stats import chi2, norm

from quadlib.model import Model, Sensor
from quadlib.validation import as_covariance, as_positive, as_probability, as_vector

__all__ = ["Innovation", "ModelFilter", "gate_threshold", "group_gates"]


class Innovation(NamedTuple):
    """What one measurement update saw.

    Attributes
    ----------
    y : (k,) ndarray
        Innovation (residual) ``z - h(x̄)``.
    S : (k, k) ndarray
        Innovation covariance.
    nis : float
        Normalised innovation squared ``yᵀ S⁻¹ y`` (χ² with k dof if consistent).
    accepted : bool
        False when the gate rejected every group and the state was left unchanged.
    rejected_groups : tuple of int
        Indices into ``sensor.groups`` of the groups the gate rejected (their components were
        not used; the other groups updated the state).
    reset : bool
        The covariance was inflated along a locked-out group before this update (see
        :meth:`ModelFilter.inflate_toward`).
    """

    y: np.ndarray
    S: np.ndarray
    nis: float
    accepted: bool
    rejected_groups: tuple = ()
    reset: bool = False


@lru_cache(maxsize=64)
def gate_threshold(dim_z: int, probability: float) -> float:
    """χ² quantile used as the NIS gate for a ``dim_z``-dimensional measurement."""
    return float(chi2.ppf(probability, dim_z))


def group_gates(sensor: Sensor, probability: float) -> tuple[float, ...]:
    """The NIS threshold of each of ``sensor.groups`` at ``probability``."""
    return tuple(gate_threshold(len(g), probability) for g in sensor.groups)


def agreement_test(sensor: Sensor, probability: float) -> tuple[np.ndarray, float]:
    """``(W, z)`` for a reset that needs agreement (``sensor.reset_needs_agreement``): ``W`` whitens a
    reading's innovation, block by block over ``sensor.groups`` (``L⁻¹`` of each group's ``R = L Lᵀ``),
    and ``z = Φ⁻¹(probability)`` sets the χ² bound on the scatter of the whitened readings
    (:func:`~quadlib.kernels.linalg.scatter_agrees`)."""
    W = np.zeros((sensor.dim_z, sensor.dim_z))
    for rows in sensor.groups:
        block = np.ix_(rows, rows)
        W[block] = np.linalg.inv(np.linalg.cholesky(sensor.R[block]))
    return W, float(norm.ppf(probability))


class ModelFilter:
    """Behaviour shared by the three wrappers (mixed in before the filterpy class).

    For an error-state model (``model.error_names`` given) filterpy's ``x`` is the error ``δx``
    and ``P`` its covariance; the full state lives in ``nominal``. After every predict and update
    the error is folded into it, ``nominal ← nominal ⊞ δx``, and reset to zero (the "reset" step
    of a multiplicative EKF). :attr:`estimate` is the full state either way.
    """

    model: Model
    nominal: np.ndarray | None

    def _setup(self, model: Model, x0, P0, dt) -> np.ndarray:
        """Check the arguments; return the initial filterpy ``x`` (the error state is zero)."""
        if not isinstance(model, Model):
            raise TypeError(f"model: expected a quadlib Model, got {type(model).__name__}")
        self._built = False  # filterpy's constructor, which runs next, sets its own Q and R: not the user's
        self._model = model
        self.dt = as_positive("dt", dt)
        x0 = as_vector("x0", x0, model.dim_x)
        if model.normalize is not None:
            x0 = as_vector("normalize(x0)", model.normalize(x0), model.dim_x)
        self._P0 = as_covariance("P0", P0, model.dim_P, definite=True)
        self._q_dt = self.dt
        self._q = as_covariance(f"{model.name}.Q(dt={self.dt:g})", model.Q(self.dt), model.dim_P)  # checked once
        self.fixed_Q = False
        self._R = None
        self.nominal = x0 if model.is_error_state else None
        self._settles = model.is_error_state or model.normalize is not None  # else a step ends as filterpy left it
        return np.zeros(model.dim_P) if model.is_error_state else x0

    # filterpy's attributes are the filter's truth: an assignment takes effect at the next step, or is refused

    @property
    def model(self) -> Model:
        """The filter's model. Assigning another (``dataclasses.replace(f.model, Q=…)``) takes effect
        at the next step: its ``Q(dt)`` is computed afresh, and a ``Q`` set by hand is dropped."""
        return self._model

    @model.setter
    def model(self, model: Model) -> None:
        old = self._model
        if not isinstance(model, Model):
            raise TypeError(f"model: expected a quadlib Model, got {type(model).__name__}")
        if (model.dim_x, model.dim_P, model.dim_u, model.is_error_state) != (
                old.dim_x, old.dim_P, old.dim_u, old.is_error_state):
            raise ValueError(f"model: expected a model of the filter's shape ({old.dim_x} states, {old.dim_P} in P, "
                             f"{old.dim_u} inputs, error state {old.is_error_state}), got {model.name!r} with "
                             f"({model.dim_x}, {model.dim_P}, {model.dim_u}, {model.is_error_state})")
        self._check_model(model)
        self._model, self._settles = model, model.is_error_state or model.normalize is not None
        self._q_dt, self.fixed_Q = -np.inf, False  # the next step computes Q(dt) from the new model

    def _check_model(self, model: Model) -> None:
        """What a filter class needs of a model besides its shape (LinearKF: linear)."""

    @property
    def Q(self) -> np.ndarray:
        """The process noise of the last step, ``Q(Δt)`` (the input's noise not included). Assigning
        it, as with filterpy, fixes ``Q`` for every later step whatever its ``Δt``; assigning ``model``
        returns to the model's ``Q(Δt)``."""
        return self._q

    @Q.setter
    def Q(self, Q) -> None:
        if not self._built:  # filterpy's constructor's default, np.eye: the model's Q(dt) stands
            return
        self._q, self.fixed_Q = as_covariance("Q", Q, self.model.dim_P), True

    @property
    def R(self) -> np.ndarray:
        """The measurement noise of the last update: its sensor's ``R``."""
        return self._R

    @R.setter
    def R(self, R) -> None:
        if self._built:
            raise AttributeError(
                "R: a quadlib filter takes each sample's noise from its sensor, so R cannot be set on the filter; "
                "give the sensor the R you want (dataclasses.replace(sensor, R=...))")
        self._R = R

    def fold_error(self) -> None:
        """Fold an error state set by hand (``f.x = δx`` on an error-state model) into the nominal state
        before the next step, as a step's end does."""
        if self.nominal is not None and self.x.any():
            self._settle()

    @property
    def estimate(self) -> np.ndarray:
        """The current state mean as a 1-D copy, shape ``(n,)`` (the full state for an error-state model)."""
        if self.nominal is not None:
            return self.nominal.copy()
        return np.array(self.x, dtype=float).reshape(-1)

    def _process_noise(self, dt: float, u: np.ndarray | None = None) -> np.ndarray:
        # Q depends on dt only. A uniform time grid asks for the same dt every step, up to float
        # jitter (the differences of 0.02 * arange(N) vary in the last bits), so Q(dt) is reused
        # while dt stays within a relative 1e-9 of the dt it was computed for. A real log's clock
        # jitters (a PX4 log has thousands of distinct steps), so a new dt's Q gets the cheap
        # checks — shape, finite, symmetric, no negative variance — and the full one (eigenvalues)
        # only if one of them fails, to name the fault; Q(self.dt) had the full check at the start.
        if not self.fixed_Q and abs(dt - self._q_dt) > 1e-9 * dt:
            q = self.model.Q(dt)
            if not (isinstance(q, np.ndarray) and q.shape == self._q.shape and np.isfinite(q).all()
                    and np.array_equal(q, q.T) and (np.diagonal(q) >= 0.0).all()):
                q = as_covariance(f"{self.model.name}.Q(dt={dt:g})", q, self.model.dim_P)
            self._q_dt, self._q = dt, q
        if self.model.input_noise is not None:
            extra = self.model.input_noise(u, dt)
            if extra is not None:
                return self._q + as_covariance(f"{self.model.name}.input_noise(u, dt={dt:g})", extra,
                                               self.model.dim_P)
        return self._q

    @property
    def reused_noise(self) -> tuple[float, np.ndarray]:
        """``(dt, Q(dt))``: the process noise the next predict reuses while its step stays within
        a relative 1e-9 of ``dt``."""
        return self._q_dt, self._q

    def continue_from(self, x, P, reused_noise: tuple[float, np.ndarray]) -> None:
        """Take the state ``x`` (the full state, ``(n,)``), the covariance ``P`` and the
        :attr:`reused_noise` that a run elsewhere (the compiled engine) ended with, unchecked."""
        x = np.array(x, dtype=float)
        if self.nominal is not None:
            self.nominal, self.x = x, np.zeros_like(self.x)
        else:
            self.x = x.reshape(self.x.shape)
        self.P = np.array(P, dtype=float)
        self._q_dt, self._q = reused_noise

    def state_view(self) -> np.ndarray:
        """The current state ``(n,)`` without a copy (read it, do not write it); see :attr:`estimate`."""
        return self.nominal if self.nominal is not None else self.x.reshape(-1)

    def _sensor_functions(self, sensor: Sensor, context):
        """``h(x)`` and ``H(x)`` of ``sensor`` for this sample (its context bound)."""
        if sensor.dim_c:
            return (lambda x: sensor.h(x, context)), (lambda x: sensor.H(x, context))
        return sensor.h, sensor.H

    def _settle(self) -> None:
        """Fold the error into the nominal state (error-state models), then apply ``normalize``."""
        m = self.model
        if m.is_error_state:
            if self.x.any():  # an EKF's predict leaves it zero: nothing to fold
                self.nominal = np.asarray(m.state_add(self.nominal, self.x.reshape(-1)), dtype=float)
                self.x = np.zeros_like(self.x)
            if m.normalize is not None:
                self.nominal = np.asarray(m.normalize(self.nominal), dtype=float)
        elif m.normalize is not None:
            x = self.x.reshape(-1)
            if m.normalize_jacobian is not None:
                J = np.asarray(m.normalize_jacobian(x), dtype=float)
                self.P = J @ self.P @ J.T
            self.x = np.asarray(m.normalize(x), dtype=float).reshape(self.x.shape)

    needs_jacobians = True  # the UKF sets False
    supports_uncorrected = False  # the EKF sets True (Sensor.uncorrected)

    def check_sensor(self, sensor, name: str = "sensor") -> Sensor:
        """Return ``sensor`` if this filter can update with it, else raise ``TypeError``/``ValueError``."""
        if not isinstance(sensor, Sensor):
            raise TypeError(f"{name}: expected a quadlib Sensor, got {type(sensor).__name__}")
        if sensor.uncorrected:
            if not self.supports_uncorrected:
                raise ValueError(f"{name}: {sensor.name!r} leaves states {sensor.uncorrected} uncorrected, which "
                                 f"{type(self).__name__} does not support (ModelEKF does)")
            if max(sensor.uncorrected) >= self.model.dim_P:
                raise ValueError(f"{name}: {sensor.name!r}.uncorrected: expected indices below {self.model.dim_P}, "
                                 f"got {sensor.uncorrected}")
        if self.needs_jacobians and sensor.H is None:
            raise ValueError(f"{name}: {sensor.name!r} has no Jacobian H; {type(self).__name__} needs one "
                             "(ModelUKF does not)")
        return sensor

    def _check_finite(self, step: str) -> None:
        # one reduction: a sum is finite only if every term is (or it overflows, near 1e308)
        total = self.x.sum() + self.P.sum() + (0.0 if self.nominal is None else self.nominal.sum())
        if not np.isfinite(total):
            raise FloatingPointError(
                f"{type(self).__name__}.{step}: the state or covariance became non-finite; "
                "check the model, Q, R and the inputs"
            )

    def predict(self, u=None, dt: float | None = None) -> None:
        """Propagate mean and covariance over ``dt`` [s] (default: the filter's ``dt``) with input ``u``."""
        dt = self.dt if dt is None else as_positive("dt", dt)
        self.predict_unchecked(self.model.check_input(u), dt)
        self._check_finite("predict")

    def predict_unchecked(self, u: np.ndarray, dt: float) -> None:
        """:meth:`predict` without argument checks, for loops that validated their whole log first."""
        self.fold_error()
        self._predict(u, dt)
        if self._settles:
            self._settle()

    def update_sensor(self, sensor: Sensor, z, gate_probability: float | None = None, context=None) -> Innovation:
        """Update with one sample of ``sensor``.

        Parameters
        ----------
        sensor : Sensor
            The measurement model.
        z : (k,) array_like
            The sample; must be finite (drop missing samples before calling).
        gate_probability : float in (0, 1), optional
            If given, each of ``sensor.groups`` whose NIS exceeds the χ² quantile
            of this probability is rejected; the state is updated with the groups
            that pass (and left as it was when none does: ``accepted`` is False).
        context : (c,) array_like, optional
            The sample's context, for a sensor with ``context_names``.

        Returns
        -------
        Innovation
        """
        sensor = self.check_sensor(sensor)
        z = sensor.check_measurement(z)
        context = sensor.check_context(context)
        gates = None
        if gate_probability is not None:
            gates = group_gates(sensor, as_probability("gate_probability", gate_probability))
        innovation = self.update_unchecked(sensor, z, gates, context)
        self._check_finite("update_sensor")
        return innovation

    def update_unchecked(self, sensor: Sensor, z: np.ndarray, gates: tuple[float, ...] | None = None,
                         context: np.ndarray | None = None, force: tuple[int, ...] = ()) -> Innovation:
        """:meth:`update_sensor` without argument checks. ``gates`` holds the NIS threshold of each
        of ``sensor.groups`` (:func:`group_gates`); groups listed in ``force`` pass whatever their NIS."""
        self.fold_error()
        if gates is not None:
            saved = (self.x.copy(), self.P.copy(), None if self.nominal is None else self.nominal.copy())
            self._before_update = saved
        self._update(sensor, z, context)
        k = sensor.dim_z
        y = self.y.reshape(k)
        S = self.S.reshape(k, k)
        nis = float(y @ self.SI.reshape(k, k) @ y)  # filterpy has already inverted S
        rejected = ()
        if gates is not None:
            if len(sensor.groups) == 1:
                rejected = (0,) if nis > gates[0] and 0 not in force else ()
            else:
                rejected = tuple(i for i, g in enumerate(sensor.groups) if i not in force
                                 and float(y[list(g)] @ np.linalg.solve(S[np.ix_(g, g)], y[list(g)])) > gates[i])
        if rejected:
            self.x, self.P, self.nominal = saved
            self.x_post, self.P_post = saved[0].copy(), saved[1].copy()
            keep = sorted(i for n, g in enumerate(sensor.groups) if n not in rejected for i in g)
            if keep:  # the groups that passed update the state on their own
                self._update(sensor.subset(keep), z[keep], context)
                if self._settles:
                    self._settle()
            return Innovation(y, S, nis, bool(keep), rejected)
        if self._settles:
            self._settle()
        return Innovation(y, S, nis, True)

    def undo_last_update(self) -> None:
        """Return to the state before the last gated :meth:`update_unchecked` (for a reset)."""
        x, P, nominal = self._before_update
        self.x, self.P, self.nominal = x.copy(), P.copy(), None if nominal is None else nominal.copy()

    def inflate_toward(self, sensor: Sensor, z: np.ndarray, groups: tuple[int, ...], context=None) -> None:
        """Widen ``P`` so that the components of ``groups`` become plausible again (a reset).

        With ``J = ∂h(x ⊞ δ)/∂δ`` (rows of ``groups``, by central differences) and the innovation
        ``y`` of those rows, ``P ← P + J⁺ diag(y²) J⁺ᵀ``: each measured direction gets the variance
        of the discrepancy it shows, so the next update moves the state most of the way to the
        measurement. For a sensor that measures states directly (GPS position) this adds ``y_i²``
        to the variance of state ``i``.
        """
        rows = sorted(i for n in groups for i in sensor.groups[n])
        h, _ = self._sensor_functions(sensor, context)
        x = self.state_view().copy()
        z_hat = np.asarray(h(x), dtype=float)
        y = np.asarray(sensor.residual(z, z_hat), dtype=float)[rows]
        eps = 1e-6 * (1.0 + np.abs(np.sqrt(np.diag(self.P))))
        J = np.empty((len(rows), self.P.shape[0]))
        for j in range(self.P.shape[0]):
            d = np.zeros(self.P.shape[0])
            d[j] = eps[j]
            plus, minus = h(self._apply_error(x, d)), h(self._apply_error(x, -d))
            J[:, j] = np.asarray(sensor.residual(plus, minus), dtype=float)[rows] / (2 * eps[j])
        J_pinv = np.linalg.pinv(J, rcond=1e-6)  # directions the sensor cannot see (below the noise) stay out
        self.P = self.P + J_pinv @ np.diag(y**2) @ J_pinv.T
        self.P = 0.5 * (self.P + self.P.T)

    def _apply_error(self, x, d):
        m = self.model
        return m.state_add(x, d) if m.is_error_state else x + d
