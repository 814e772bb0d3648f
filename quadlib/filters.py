"""Thin wrappers that make filterpy's filters run a :class:`~quadlib.model.Model`.

All three wrappers are subclasses of the filterpy class they wrap, so every
filterpy attribute (``x``, ``P``, ``K``, ``S``, ``y``, ``x_prior`` …) is there
as documented by filterpy. They add one common interface:

* ``predict(u, dt)`` — propagate with the model's ``g`` (or its sigma points)
  and ``Q(dt)``;
* ``update_sensor(sensor, z, gate_probability=None)`` — update with a
  :class:`~quadlib.model.Sensor`, optionally rejecting outliers whose
  normalised innovation squared exceeds the χ² quantile;
* ``estimate`` — the state as a 1-D copy.

Why the EKF wrapper exists: filterpy's ``ExtendedKalmanFilter.predict`` moves
the mean with the *linear* ``F x + B u`` unless ``predict_x`` is overridden,
so a user who only sets ``F`` to the Jacobian silently runs the wrong filter.
:class:`ModelEKF` moves the mean with the nonlinear ``g`` and the covariance
with its Jacobian ``G`` evaluated at the previous mean (Tellex et al. §3,
Algorithm 2, lines 2–4).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from filterpy.kalman import (
    ExtendedKalmanFilter,
    KalmanFilter,
    MerweScaledSigmaPoints,
    UnscentedKalmanFilter,
)
from scipy.stats import chi2

from quadlib.model import Model, Sensor
from quadlib.validation import as_covariance, as_positive, as_probability, as_vector

__all__ = ["Innovation", "LinearKF", "ModelEKF", "ModelFilter", "ModelUKF", "gate_threshold"]


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
        False when the gate rejected the sample and the state was left unchanged.
    """

    y: np.ndarray
    S: np.ndarray
    nis: float
    accepted: bool


@lru_cache(maxsize=64)
def gate_threshold(dim_z: int, probability: float) -> float:
    """χ² quantile used as the NIS gate for a ``dim_z``-dimensional measurement."""
    return float(chi2.ppf(probability, dim_z))


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
        self.model = model
        self.dt = as_positive("dt", dt)
        x0 = as_vector("x0", x0, model.dim_x)
        if model.normalize is not None:
            x0 = as_vector("normalize(x0)", model.normalize(x0), model.dim_x)
        self._P0 = as_covariance("P0", P0, model.dim_P)
        self._q_dt = self.dt
        self._q = as_covariance(f"{model.name}.Q(dt={self.dt:g})", model.Q(self.dt), model.dim_P)  # checked once
        self.nominal = x0 if model.is_error_state else None
        return np.zeros(model.dim_P) if model.is_error_state else x0

    @property
    def estimate(self) -> np.ndarray:
        """The current state mean as a 1-D copy, shape ``(n,)`` (the full state for an error-state model)."""
        if self.nominal is not None:
            return self.nominal.copy()
        return np.array(self.x, dtype=float).reshape(-1)

    def _process_noise(self, dt: float) -> np.ndarray:
        # Q depends on dt only. A uniform time grid asks for the same dt every step, up to float
        # jitter (the differences of 0.02 * arange(N) vary in the last bits), so Q(dt) is reused
        # while dt stays within a relative 1e-9 of the dt it was computed for.
        if abs(dt - self._q_dt) > 1e-9 * dt:
            self._q_dt, self._q = dt, np.asarray(self.model.Q(dt), dtype=float)
        return self._q

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
            self.x = np.asarray(m.normalize(self.x.reshape(-1)), dtype=float).reshape(self.x.shape)

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
        self._predict(u, dt)
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
            If given, a sample whose NIS exceeds the χ² quantile of this
            probability (``k`` dof) is rejected: the state and covariance are
            left as they were and ``accepted`` is False.
        context : (c,) array_like, optional
            The sample's context, for a sensor with ``context_names``.

        Returns
        -------
        Innovation
        """
        if not isinstance(sensor, Sensor):
            raise TypeError(f"sensor: expected a quadlib Sensor, got {type(sensor).__name__}")
        z = sensor.check_measurement(z)
        context = sensor.check_context(context)
        gate = None
        if gate_probability is not None:
            gate = gate_threshold(sensor.dim_z, as_probability("gate_probability", gate_probability))
        innovation = self.update_unchecked(sensor, z, gate, context)
        self._check_finite("update_sensor")
        return innovation

    def update_unchecked(self, sensor: Sensor, z: np.ndarray, gate: float | None = None,
                         context: np.ndarray | None = None) -> Innovation:
        """:meth:`update_sensor` without argument checks; ``gate`` is the NIS threshold itself."""
        if gate is not None:
            saved = (self.x.copy(), self.P.copy(), None if self.nominal is None else self.nominal.copy())
        self._update(sensor, z, context)
        k = sensor.dim_z
        y = self.y.reshape(k)
        S = self.S.reshape(k, k)
        nis = float(y @ self.SI.reshape(k, k) @ y)  # filterpy has already inverted S
        accepted = gate is None or nis <= gate
        if accepted:
            self._settle()
        else:
            self.x, self.P, self.nominal = saved
            self.x_post, self.P_post = saved[0].copy(), saved[1].copy()
        return Innovation(y, S, nis, accepted)


class LinearKF(ModelFilter, KalmanFilter):
    """filterpy ``KalmanFilter`` driven by a linear :class:`Model`.

    The model must satisfy ``g(x, u, dt) = G(dt) x + B(dt) u`` and every sensor
    ``h(x) = H x``; both are checked, so a nonlinear model is refused instead
    of being linearised silently. This is Tellex et al. Algorithm 2 with
    ``G`` and ``H`` that ignore the state.

    Parameters
    ----------
    model : Model
        A linear model with ``B`` given when it has inputs.
    x0 : (n,) array_like
        Initial mean.
    P0 : (n, n) array_like
        Initial covariance.
    dt : float
        Default step [s] for :meth:`predict`.
    """

    def __init__(self, model: Model, x0, P0, dt: float):
        x0 = self._setup(model, x0, P0, dt)
        if model.is_error_state or model.normalize is not None or model.G is None:
            raise ValueError(f"model: {model.name!r} needs G and no error state or normalize for LinearKF; "
                             "use ModelEKF or ModelUKF")
        if model.dim_u and model.B is None:
            raise ValueError(f"model: {model.name!r} has inputs but no B(x, u, dt); LinearKF needs it")
        KalmanFilter.__init__(self, dim_x=model.dim_x, dim_z=1, dim_u=model.dim_u)
        self.x = x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._linear_sensors: dict[int, Sensor] = {}  # id -> sensor; holding it keeps the id from being reused
        self._check_model_linear()

    def _check_model_linear(self) -> None:
        rng = np.random.default_rng(0)
        m = self.model
        for _ in range(2):
            x, u = rng.normal(size=m.dim_x), rng.normal(size=m.dim_u)
            F = np.asarray(m.G(x, u, self.dt), dtype=float)
            gx = F @ x + (np.asarray(m.B(x, u, self.dt)) @ u if m.dim_u else 0.0)
            if not np.allclose(m.g(x, u, self.dt), gx, rtol=1e-9, atol=1e-12):
                raise ValueError(
                    f"model: {m.name!r} is not linear (g(x, u, dt) != G x + B u); use ModelEKF or ModelUKF"
                )

    def _check_sensor_linear(self, sensor: Sensor) -> None:
        if self._linear_sensors.get(id(sensor)) is sensor:
            return
        if sensor.residual is not np.subtract or sensor.dim_c:
            raise ValueError(f"sensor: {sensor.name!r} has a custom residual or a context; LinearKF only "
                             "supports z - Hx")
        x = np.random.default_rng(1).normal(size=self.model.dim_x)
        if not np.allclose(sensor.h(x), np.asarray(sensor.H(x)) @ x, rtol=1e-9, atol=1e-12):
            raise ValueError(f"sensor: {sensor.name!r} is not linear (h(x) != H x); use ModelEKF or ModelUKF")
        self._linear_sensors[id(sensor)] = sensor

    def _predict(self, u: np.ndarray, dt: float) -> None:
        m = self.model
        x = self.x[:, 0]
        F = np.asarray(m.G(x, u, dt), dtype=float)
        B = np.asarray(m.B(x, u, dt), dtype=float) if m.dim_u else None
        KalmanFilter.predict(self, u=u.reshape(-1, 1) if m.dim_u else None, B=B, F=F, Q=self._process_noise(dt))

    def _update(self, sensor: Sensor, z: np.ndarray, context) -> None:
        self._check_sensor_linear(sensor)
        H = np.asarray(sensor.H(self.estimate), dtype=float)
        KalmanFilter.update(self, z.reshape(-1, 1), R=sensor.R, H=H)


class ModelEKF(ModelFilter, ExtendedKalmanFilter):
    """filterpy ``ExtendedKalmanFilter`` whose predict applies the nonlinear ``g``.

    .. math::

        \\bar\\mu = g(\\mu, u, \\Delta t), \\quad
        \\bar\\Sigma = G \\Sigma G^\\top + Q(\\Delta t), \\quad G = G(\\mu, u, \\Delta t)

    The update is filterpy's, with the sensor's ``h``, ``H``, ``R`` and
    residual, and the Joseph-form covariance update. With an error-state model
    this is the multiplicative EKF: filterpy's ``x`` is the error, ``G`` and
    ``H`` are taken with respect to it, and each update ends with the reset
    ``x ← x ⊞ δx``, ``δx ← 0`` (see :class:`ModelFilter`).

    Parameters
    ----------
    model : Model
        Must have a Jacobian ``G``.
    x0 : (n,) array_like
    P0 : (p, p) array_like
        Over the error state for an error-state model.
    dt : float
        Default step [s].
    """

    def __init__(self, model: Model, x0, P0, dt: float):
        x0 = self._setup(model, x0, P0, dt)
        if model.G is None:
            raise ValueError(f"model: {model.name!r} has no Jacobian G; ModelEKF needs one (ModelUKF does not)")
        ExtendedKalmanFilter.__init__(self, dim_x=model.dim_P, dim_z=1, dim_u=model.dim_u)
        self.x = x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._step = None

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # filterpy's predict calls predict_x (below, the nonlinear g), then P = F P Fᵀ + Q
        x = self.nominal if self.nominal is not None else self.x[:, 0]
        self.F = np.asarray(self.model.G(x, u, dt), dtype=float)
        self.Q = self._process_noise(dt)
        self._step = (x, u, dt)
        ExtendedKalmanFilter.predict(self, u)

    def predict_x(self, u=0) -> None:
        """Mean prediction with the model's ``g`` (replaces filterpy's ``F x + B u``); for an
        error-state model the nominal state moves and the error stays zero."""
        x, u, dt = self._step
        x_new = np.asarray(self.model.g(x, u, dt), dtype=float)
        if self.nominal is not None:
            self.nominal = x_new
        else:
            self.x = x_new.reshape(-1, 1)

    def _update(self, sensor: Sensor, z: np.ndarray, context) -> None:
        h, H = self._sensor_functions(sensor, context)
        if sensor.residual is np.subtract:
            residual = np.subtract
        else:
            def residual(a, b):
                return np.asarray(sensor.residual(a[:, 0], b[:, 0]), dtype=float).reshape(-1, 1)
        if self.nominal is not None:  # linearised at the nominal state, where the error is zero
            nominal, chain = self.nominal, self.model.add_jacobian
            H_error = np.asarray(H(nominal), dtype=float)
            if chain is not None:
                H_error = H_error @ np.asarray(chain(nominal), dtype=float)
            Hx, HJacobian = (lambda e: np.asarray(h(nominal), dtype=float).reshape(-1, 1), lambda e: H_error)
        else:
            Hx, HJacobian = (lambda x: np.asarray(h(x[:, 0]), dtype=float).reshape(-1, 1),
                             lambda x: np.asarray(H(x[:, 0]), dtype=float))
        ExtendedKalmanFilter.update(self, z.reshape(-1, 1), HJacobian=HJacobian, Hx=Hx, R=sensor.R,
                                    residual=residual)


def _no_default_hx(x):
    raise RuntimeError("ModelUKF has no default measurement function: call update_sensor(sensor, z)")


class ModelUKF(ModelFilter, UnscentedKalmanFilter):
    """filterpy ``UnscentedKalmanFilter`` whose process function receives the input ``u``.

    With an error-state model the sigma points are spread in the error space
    around the nominal state, each mapped through ``x ⊞ δx`` before ``g`` or
    ``h`` and back with ``⊟`` after ``g``; the mean error is then folded into
    the nominal state (see :class:`ModelFilter`). Quaternions thus never meet
    a weighted average, and the plain filterpy mean and residual are right.

    Parameters
    ----------
    model : Model
        ``G`` is not used.
    x0 : (n,) array_like
    P0 : (p, p) array_like
    dt : float
        Default step [s].
    alpha, beta, kappa : float
        Van der Merwe's scaled sigma-point parameters (Tellex et al. §4,
        eqs. 7–10); ignored when ``points`` is given.
    points : filterpy sigma-point object, optional
        Overrides the default ``MerweScaledSigmaPoints``.
    x_mean_fn, residual_x, state_add : callable, optional
        Passed to filterpy for additive states that hold angles (not with an
        error-state model, which brings its own); ``residual_x`` is also used
        to spread the sigma points.

    Notes
    -----
    Differs from plain filterpy: an update always uses sigma points drawn
    from the current ``(x, P)``. filterpy reuses those of the last predict,
    which is wrong for an update before the first predict, for the second of
    two sensors updating in the same step, and after ``x`` or ``P`` was edited;
    ``ModelUKF`` compares values, so ``f.x[0] = 5`` and ``f.x = new`` act alike.
    """

    def __init__(self, model: Model, x0, P0, dt: float, *, alpha: float = 0.5, beta: float = 2.0,
                 kappa: float = 0.0, points=None, x_mean_fn=None, residual_x=None, state_add=None):
        x0 = self._setup(model, x0, P0, dt)
        if model.is_error_state and any(f is not None for f in (x_mean_fn, residual_x, state_add)):
            raise ValueError(f"model: {model.name!r} is an error-state model; its own state_add and residual_x "
                             "are used, so x_mean_fn, residual_x and state_add must not be given")
        if points is None:
            points = MerweScaledSigmaPoints(
                model.dim_P, alpha=as_positive("alpha", alpha), beta=float(beta), kappa=float(kappa),
                subtract=residual_x,
            )
        UnscentedKalmanFilter.__init__(
            self, dim_x=model.dim_P, dim_z=1, dt=self.dt, hx=_no_default_hx,
            fx=self._error_fx if model.is_error_state else (lambda x, dt, u: model.g(x, u, dt)), points=points,
            x_mean_fn=x_mean_fn, residual_x=residual_x, state_add=state_add,
        )
        self.x = x0
        self.P = self._P0.copy()
        self._drawn = (None, None)
        self._fx_refs = (None, None)

    def _error_fx(self, e, dt, u):
        """Error after one step of a sigma point: ``g(x₀ ⊞ e, u, dt) ⊟ g(x₀, u, dt)``."""
        before, after = self._fx_refs
        m = self.model
        return m.residual_x(m.g(m.state_add(before, e), u, dt), after)

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # propagate the sigma points through g(x, u, dt), then add Q(dt)
        self.Q = self._process_noise(dt)
        if self.nominal is not None:
            after = np.asarray(self.model.g(self.nominal, u, dt), dtype=float)
            self._fx_refs = (self.nominal, after)
            UnscentedKalmanFilter.predict(self, dt=dt, u=u)
            self.nominal = after
        else:
            UnscentedKalmanFilter.predict(self, dt=dt, u=u)
        self._drawn = (self.x.copy(), self.P.copy())  # filterpy ends predict by redrawing them here

    def _update(self, sensor: Sensor, z: np.ndarray, context) -> None:
        drawn_x, drawn_P = self._drawn
        if drawn_x is None or not (np.array_equal(drawn_x, self.x) and np.array_equal(drawn_P, self.P)):
            self.sigmas_f = self.points_fn.sigma_points(self.x, self.P)
        h, _ = self._sensor_functions(sensor, context)
        if self.nominal is not None:
            nominal, add = self.nominal, self.model.state_add
            hx = lambda e: h(add(nominal, e))  # noqa: E731
        else:
            hx = h
        self.residual_z = sensor.residual
        self.z_mean = sensor.mean
        UnscentedKalmanFilter.update(self, z, R=sensor.R, hx=hx)
        self._drawn = (None, None)
