"""Thin wrappers that make filterpy's filters run a :class:`~quadlib.model.Model`.

All three wrappers are subclasses of the filterpy class they wrap, so every
filterpy attribute (``x``, ``P``, ``K``, ``S``, ``y``, ``x_prior`` …) is there
as documented by filterpy. They add one common interface, from
:class:`~quadlib.model_filter.ModelFilter`:

* ``predict(u, dt)`` — propagate with the model's ``g`` (or its sigma points)
  and ``Q(dt)``;
* ``update_sensor(sensor, z, gate_probability=None, context=None)`` — update
  with a :class:`~quadlib.model.Sensor`, optionally rejecting outliers whose
  normalised innovation squared exceeds the χ² quantile;
* ``estimate`` — the state as a 1-D copy (the full state of an error-state model).

Why the EKF wrapper exists: filterpy's ``ExtendedKalmanFilter.predict`` moves
the mean with the *linear* ``F x + B u`` unless ``predict_x`` is overridden,
so a user who only sets ``F`` to the Jacobian silently runs the wrong filter.
:class:`ModelEKF` moves the mean with the nonlinear ``g`` and the covariance
with its Jacobian ``G`` evaluated at the previous mean (Tellex et al. §3,
Algorithm 2, lines 2–4).
"""

from __future__ import annotations

import numpy as np
from filterpy.kalman import (
    ExtendedKalmanFilter,
    KalmanFilter,
    MerweScaledSigmaPoints,
    UnscentedKalmanFilter,
    unscented_transform,
)
from scipy.linalg.lapack import dpotrf

from quadlib.model import Model, Sensor
from quadlib.model_filter import ModelFilter
from quadlib.validation import as_positive

__all__ = ["LinearKF", "ModelEKF", "ModelUKF"]


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
        self._check_model(model)
        KalmanFilter.__init__(self, dim_x=model.dim_x, dim_z=1, dim_u=model.dim_u)
        self.x = x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._linear_sensors: dict[int, Sensor] = {}  # id -> sensor; holding it keeps the id from being reused
        self._check_model(model)
        self._built = True

    def _check_model(self, m: Model) -> None:
        if m.is_error_state or m.normalize is not None or m.G is None:
            raise ValueError(f"model: {m.name!r} needs G and no error state or normalize for LinearKF; "
                             "use ModelEKF or ModelUKF")
        if m.dim_u and m.B is None:
            raise ValueError(f"model: {m.name!r} has inputs but no B(x, u, dt); LinearKF needs it")
        rng = np.random.default_rng(0)
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
        KalmanFilter.predict(self, u=u.reshape(-1, 1) if m.dim_u else None, B=B, F=F, Q=self._process_noise(dt, u))

    def _update(self, sensor: Sensor, z: np.ndarray, context) -> None:
        self._check_sensor_linear(sensor)
        H = np.asarray(sensor.H(self.estimate), dtype=float)
        self._R = sensor.R
        KalmanFilter.update(self, z.reshape(-1, 1), R=sensor.R, H=H)


class ModelEKF(ModelFilter, ExtendedKalmanFilter):
    """filterpy ``ExtendedKalmanFilter`` whose predict applies the nonlinear ``g``.

    .. math::

        \\bar\\mu = g(\\mu, u, \\Delta t), \\quad
        \\bar\\Sigma = G \\Sigma G^\\top + Q(\\Delta t), \\quad G = G(\\mu, u, \\Delta t)

    The update is filterpy's (written out, tested equal to it), with the
    sensor's ``h``, ``H``, ``R`` and residual, and the Joseph-form covariance
    update. With an error-state model
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

    supports_uncorrected = True

    def __init__(self, model: Model, x0, P0, dt: float):
        x0 = self._setup(model, x0, P0, dt)
        self._check_model(model)
        ExtendedKalmanFilter.__init__(self, dim_x=model.dim_P, dim_z=1, dim_u=model.dim_u)
        self.x = x0.reshape(-1, 1)
        self.P = self._P0.copy()
        self._step = None
        self._built = True

    def _check_model(self, model: Model) -> None:
        if model.G is None:
            raise ValueError(f"model: {model.name!r} has no Jacobian G; ModelEKF needs one (ModelUKF does not)")

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # filterpy's predict, written out: predict_x (below, the nonlinear g), then P = F P Fᵀ + Q with
        # the step's Q (the model's, or one set by hand, plus the input's noise)
        x = self.nominal if self.nominal is not None else self.x[:, 0]
        self.F = np.asarray(self.model.G(x, u, dt), dtype=float)
        Q = self._process_noise(dt, u)
        self._step = (x, u, dt)
        self.predict_x(u)
        self.P = np.dot(self.F, self.P).dot(self.F.T) + Q
        self.x_prior, self.P_prior = np.copy(self.x), np.copy(self.P)

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
        # filterpy's ExtendedKalmanFilter.update, written out for one sample: the same equations
        # and attributes (y, S, SI, K, x_post, P_post), without its per-call argument handling
        h, H = self._sensor_functions(sensor, context)
        if self.nominal is not None:  # linearised at the nominal state, where the error is zero
            at = self.nominal
            H_x = np.asarray(H(at), dtype=float)
            if self.model.add_jacobian is not None:
                H_x = H_x @ np.asarray(self.model.add_jacobian(at), dtype=float)
        else:
            at = self.x[:, 0]
            H_x = np.asarray(H(at), dtype=float)
        z_hat = np.asarray(h(at), dtype=float)
        y = z - z_hat if sensor.residual is np.subtract else np.asarray(sensor.residual(z, z_hat), dtype=float)
        R = self._R = sensor.R
        PHT = self.P @ H_x.T
        self.S = H_x @ PHT + R
        self.SI = 1.0 / self.S if self.S.shape == (1, 1) else np.linalg.inv(self.S)  # one division is LAPACK's 1x1
        self.K = PHT @ self.SI
        if sensor.uncorrected:  # a consider update: those states keep their value; Joseph's P stays exact
            self.K[list(sensor.uncorrected)] = 0.0
        self.y = y.reshape(-1, 1)
        self.x = self.x + self.K @ self.y
        I_KH = self._I - self.K @ H_x
        self.P = I_KH @ self.P @ I_KH.T + self.K @ R @ self.K.T
        self.z = z.reshape(-1, 1).copy()
        self.x_post, self.P_post = self.x.copy(), self.P.copy()
        self._log_likelihood = self._likelihood = self._mahalanobis = None


def sigma_point_sqrt(P: np.ndarray) -> np.ndarray:
    """``U`` with ``Uᵀ U = P``: what ``scipy.linalg.cholesky(P)``, filterpy's default for the sigma
    points, returns (the same LAPACK routine, so the same bits), without its argument handling,
    which cost 8× the factorisation of a small ``P``."""
    if not np.isfinite(P).all():
        raise ValueError("P: expected a finite covariance for the sigma points, got infs or NaNs")
    U, info = dpotrf(P, lower=0, clean=1)
    if info > 0:
        raise np.linalg.LinAlgError(f"{info}-th leading minor of the array is not positive definite")
    return U


def positive_definite(P: np.ndarray) -> np.ndarray:
    """``P`` symmetrised and, if rounding made it indefinite, with its eigenvalues raised to a
    floor of 1e-12 of the largest. The UKF's ``P − K S Kᵀ`` (unlike the EKF's Joseph form) loses
    definiteness when a very precise sensor meets a very uncertain state."""
    P = 0.5 * (P + P.T)
    try:
        np.linalg.cholesky(P)
        return P
    except np.linalg.LinAlgError:
        w, V = np.linalg.eigh(P)
        return (V * np.maximum(w, 1e-12 * max(float(w.max()), np.finfo(float).tiny))) @ V.T


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

    needs_jacobians = False

    def __init__(self, model: Model, x0, P0, dt: float, *, alpha: float = 0.5, beta: float = 2.0,
                 kappa: float = 0.0, points=None, x_mean_fn=None, residual_x=None, state_add=None):
        x0 = self._setup(model, x0, P0, dt)
        if model.is_error_state and any(f is not None for f in (x_mean_fn, residual_x, state_add)):
            raise ValueError(f"model: {model.name!r} is an error-state model; its own state_add and residual_x "
                             "are used, so x_mean_fn, residual_x and state_add must not be given")
        if points is None:
            points = MerweScaledSigmaPoints(
                model.dim_P, alpha=as_positive("alpha", alpha), beta=float(beta), kappa=float(kappa),
                sqrt_method=sigma_point_sqrt, subtract=residual_x,
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
        self._built = True

    def _error_fx(self, e, dt, u):
        """Error after one step of a sigma point: ``g(x₀ ⊞ e, u, dt) ⊟ g(x₀, u, dt)``."""
        before, after = self._fx_refs
        m = self.model
        return m.residual_x(m.g(m.state_add(before, e), u, dt), after)

    def _predict(self, u: np.ndarray, dt: float) -> None:
        # propagate the sigma points through g(x, u, dt), then add the step's Q (the model's, or one set by
        # hand, plus the input's noise)
        Q = self._process_noise(dt, u)
        transform = lambda sigmas, Wm, Wc, _, mean, residual: unscented_transform(  # noqa: E731
            sigmas, Wm, Wc, Q, mean, residual)
        if self.nominal is not None:
            after = np.asarray(self.model.g(self.nominal, u, dt), dtype=float)
            self._fx_refs = (self.nominal, after)
            UnscentedKalmanFilter.predict(self, dt=dt, UT=transform, u=u)
            self.nominal = after
        else:
            UnscentedKalmanFilter.predict(self, dt=dt, UT=transform, u=u)
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
        self._R = sensor.R
        UnscentedKalmanFilter.update(self, z, R=sensor.R, hx=hx)
        self.P = positive_definite(self.P)
        self._drawn = (None, None)
