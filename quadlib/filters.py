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

from .model import Model, Sensor
from .validation import as_covariance, as_positive, as_probability, as_vector

__all__ = ["Innovation", "LinearKF", "ModelEKF", "ModelUKF", "gate_threshold"]


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


class _ModelFilter:
    """Behaviour shared by the three wrappers (mixed in before the filterpy class)."""

    model: Model

    def _setup(self, model: Model, x0, P0, dt) -> None:
        if not isinstance(model, Model):
            raise TypeError(f"model: expected a quadlib Model, got {type(model).__name__}")
        self.model = model
        self.dt = as_positive("dt", dt)
        self._x0 = as_vector("x0", x0, model.dim_x)
        self._P0 = as_covariance("P0", P0, model.dim_x)
        self._q_dt = self.dt
        self._q = as_covariance(f"{model.name}.Q(dt={self.dt:g})", model.Q(self.dt), model.dim_x)  # checked once

    @property
    def estimate(self) -> np.ndarray:
        """The current state mean as a 1-D copy, shape ``(n,)``."""
        return np.array(self.x, dtype=float).reshape(-1)

    def _process_noise(self, dt: float) -> np.ndarray:
        # Q depends on dt only. A uniform time grid asks for the same dt every step, up to float
        # jitter (the differences of 0.02 * arange(N) vary in the last bits), so Q(dt) is reused
        # while dt stays within a relative 1e-9 of the dt it was computed for.
        if abs(dt - self._q_dt) > 1e-9 * dt:
            self._q_dt, self._q = dt, np.asarray(self.model.Q(dt), dtype=float)
        return self._q

    def _check_finite(self, step: str) -> None:
        # one reduction: a sum is finite only if every term is (or it overflows, near 1e308)
        if not np.isfinite(self.x.sum() + self.P.sum()):
            raise FloatingPointError(
                f"{type(self).__name__}.{step}: the state or covariance became non-finite; "
                "check the model, Q, R and the inputs"
            )

    def predict(self, u=None, dt: float | None = None) -> None:
        """Propagate mean and covariance over ``dt`` [s] (default: the filter's ``dt``) with input ``u``."""
        dt = self.dt if dt is None else as_positive("dt", dt)
        self._predict(self.model.check_input(u), dt)
        self._check_finite("predict")

    def update_sensor(self, sensor: Sensor, z, gate_probability: float | None = None) -> Innovation:
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

        Returns
        -------
        Innovation
        """
        if not isinstance(sensor, Sensor):
            raise TypeError(f"sensor: expected a quadlib Sensor, got {type(sensor).__name__}")
        z = sensor.check_measurement(z)
        gate = None
        if gate_probability is not None:
            gate = gate_threshold(sensor.dim_z, as_probability("gate_probability", gate_probability))
        innovation = self._update_sensor(sensor, z, gate)
        self._check_finite("update_sensor")
        return innovation

    def _update_sensor(self, sensor: Sensor, z: np.ndarray, gate: float | None) -> Innovation:
        """Update without argument checks (callers have validated ``sensor`` and ``z``)."""
        if gate is not None:
            saved = (self.x.copy(), self.P.copy())
        self._update(sensor, z)
        k = sensor.dim_z
        y = self.y.reshape(k)
        S = self.S.reshape(k, k)
        nis = float(y @ self.SI.reshape(k, k) @ y)  # filterpy has already inverted S
        accepted = gate is None or nis <= gate
        if not accepted:
            self.x, self.P = saved
            self.x_post, self.P_post = saved[0].copy(), saved[1].copy()
        return Innovation(y, S, nis, accepted)


class LinearKF(_ModelFilter, KalmanFilter):
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
        self._setup(model, x0, P0, dt)
        if model.dim_u and model.B is None:
            raise ValueError(f"model: {model.name!r} has inputs but no B(x, u, dt); LinearKF needs it")
        KalmanFilter.__init__(self, dim_x=model.dim_x, dim_z=1, dim_u=model.dim_u)
        self.x = self._x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._linear_checked: set[int] = set()
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
        if id(sensor) in self._linear_checked:
            return
        if sensor.residual is not np.subtract:
            raise ValueError(f"sensor: {sensor.name!r} has a custom residual; LinearKF only supports z - Hx")
        x = np.random.default_rng(1).normal(size=self.model.dim_x)
        if not np.allclose(sensor.h(x), np.asarray(sensor.H(x)) @ x, rtol=1e-9, atol=1e-12):
            raise ValueError(f"sensor: {sensor.name!r} is not linear (h(x) != H x); use ModelEKF or ModelUKF")
        self._linear_checked.add(id(sensor))

    def _predict(self, u: np.ndarray, dt: float) -> None:
        m = self.model
        x = self.x[:, 0]
        F = np.asarray(m.G(x, u, dt), dtype=float)
        B = np.asarray(m.B(x, u, dt), dtype=float) if m.dim_u else None
        KalmanFilter.predict(self, u=u.reshape(-1, 1) if m.dim_u else None, B=B, F=F, Q=self._process_noise(dt))

    def _update(self, sensor: Sensor, z: np.ndarray) -> None:
        self._check_sensor_linear(sensor)
        H = np.asarray(sensor.H(self.estimate), dtype=float)
        KalmanFilter.update(self, z.reshape(-1, 1), R=sensor.R, H=H)


class ModelEKF(_ModelFilter, ExtendedKalmanFilter):
    """filterpy ``ExtendedKalmanFilter`` whose predict applies the nonlinear ``g``.

    .. math::

        \\bar\\mu = g(\\mu, u, \\Delta t), \\quad
        \\bar\\Sigma = G \\Sigma G^\\top + Q(\\Delta t), \\quad G = G(\\mu, u, \\Delta t)

    The update is filterpy's, with the sensor's ``h``, ``H``, ``R`` and
    residual, and the Joseph-form covariance update.

    Parameters
    ----------
    model : Model
    x0 : (n,) array_like
    P0 : (n, n) array_like
    dt : float
        Default step [s].
    """

    def __init__(self, model: Model, x0, P0, dt: float):
        self._setup(model, x0, P0, dt)
        ExtendedKalmanFilter.__init__(self, dim_x=model.dim_x, dim_z=1, dim_u=model.dim_u)
        self.x = self._x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._step = None

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # filterpy's predict calls predict_x (below, the nonlinear g), then P = F P Fᵀ + Q
        x = self.x[:, 0]
        self.F = np.asarray(self.model.G(x, u, dt), dtype=float)
        self.Q = self._process_noise(dt)
        self._step = (x, u, dt)
        ExtendedKalmanFilter.predict(self, u)

    def predict_x(self, u=0) -> None:
        """Mean prediction with the model's ``g`` (replaces filterpy's ``F x + B u``)."""
        x, u, dt = self._step
        self.x = np.asarray(self.model.g(x, u, dt), dtype=float).reshape(-1, 1)

    def _update(self, sensor: Sensor, z: np.ndarray) -> None:
        if sensor.residual is np.subtract:
            residual = np.subtract
        else:
            def residual(a, b):
                return np.asarray(sensor.residual(a[:, 0], b[:, 0]), dtype=float).reshape(-1, 1)
        ExtendedKalmanFilter.update(
            self,
            z.reshape(-1, 1),
            HJacobian=lambda x: np.asarray(sensor.H(x[:, 0]), dtype=float),
            Hx=lambda x: np.asarray(sensor.h(x[:, 0]), dtype=float).reshape(-1, 1),
            R=sensor.R,
            residual=residual,
        )


def _no_default_hx(x):
    raise RuntimeError("ModelUKF has no default measurement function: call update_sensor(sensor, z)")


class ModelUKF(_ModelFilter, UnscentedKalmanFilter):
    """filterpy ``UnscentedKalmanFilter`` whose process function receives the input ``u``.

    Parameters
    ----------
    model : Model
    x0 : (n,) array_like
    P0 : (n, n) array_like
    dt : float
        Default step [s].
    alpha, beta, kappa : float
        Van der Merwe's scaled sigma-point parameters (Tellex et al. §4,
        eqs. 7–10); ignored when ``points`` is given.
    points : filterpy sigma-point object, optional
        Overrides the default ``MerweScaledSigmaPoints``.
    x_mean_fn, residual_x, state_add : callable, optional
        Passed to filterpy for states that are not plain vectors (angles,
        quaternions); ``residual_x`` is also used to spread the sigma points.

    Notes
    -----
    Differs from plain filterpy: an update always uses sigma points drawn
    from the current ``(x, P)``. filterpy reuses those of the last predict,
    which is wrong for an update before the first predict and for the second
    of two sensors updating in the same step; ``ModelUKF`` redraws them then.
    """

    def __init__(self, model: Model, x0, P0, dt: float, *, alpha: float = 0.5, beta: float = 2.0,
                 kappa: float = 0.0, points=None, x_mean_fn=None, residual_x=None, state_add=None):
        self._setup(model, x0, P0, dt)
        if points is None:
            points = MerweScaledSigmaPoints(
                model.dim_x, alpha=as_positive("alpha", alpha), beta=float(beta), kappa=float(kappa),
                subtract=residual_x,
            )
        UnscentedKalmanFilter.__init__(
            self, dim_x=model.dim_x, dim_z=1, dt=self.dt, hx=_no_default_hx,
            fx=lambda x, dt, u: model.g(x, u, dt), points=points,
            x_mean_fn=x_mean_fn, residual_x=residual_x, state_add=state_add,
        )
        self.x = self._x0.copy()
        self.P = self._P0.copy()
        self._sigmas_drawn_from = (None, None)

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # propagate the sigma points through g(x, u, dt), then add Q(dt)
        self.Q = self._process_noise(dt)
        UnscentedKalmanFilter.predict(self, dt=dt, u=u)
        self._sigmas_drawn_from = (self.x, self.P)

    def _update(self, sensor: Sensor, z: np.ndarray) -> None:
        # filterpy updates with the sigma points of the last predict: zeros before the
        # first predict, and stale after an earlier update in the same step (a second
        # sensor). Redraw them from the current mean and covariance, unless a predict
        # (which ends by redrawing them from its result) produced the current x and P.
        drawn_x, drawn_P = self._sigmas_drawn_from
        if drawn_x is not self.x or drawn_P is not self.P:
            self.sigmas_f = self.points_fn.sigma_points(self.x, self.P)
        self.residual_z = sensor.residual
        self.z_mean = sensor.mean
        UnscentedKalmanFilter.update(self, z, R=sensor.R, hx=sensor.h)
