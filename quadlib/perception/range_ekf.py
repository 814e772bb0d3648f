"""The single-Gaussian alternative to the particle filter: an EKF on the same robot and scans.

State ``x = (x, y, ψ)`` [m, m, rad]; input the odometry ``u = (v, ω)``; one step of length ``Δt``
drives along the heading turned by half the step's turn (as :func:`odometry_step`):

.. math::

    x^+ = x + v\\Delta t\\cos(\\psi + \\tfrac12\\omega\\Delta t), \\quad
    y^+ = y + v\\Delta t\\sin(\\psi + \\tfrac12\\omega\\Delta t), \\quad \\psi^+ = \\psi + \\omega\\Delta t

The measurement is the scan's ranges, each clipped at the lidar's range (no return reads as the
maximum, as in the particle filter's likelihood); its Jacobian is taken by central differences of
the ray casting, since a range is a piecewise smooth function of the pose (it jumps where a beam
passes a corner). The process noise is the odometry's, ``σ_v Δt`` on both position axes (the
heading's direction is left out, which makes it a little generous across the track) and ``σ_ω Δt`` on
the heading.
"""

from __future__ import annotations

import numpy as np

from quadlib.model import Model, Sensor
from quadlib.perception.lidar import cast_rays
from quadlib.validation import as_finite_array, as_positive, as_vector

__all__ = ["scan_range_sensor", "unicycle_model"]


def unicycle_model(odometry_sigma=(0.05, 0.02)) -> Model:
    """The robot of the module documentation, with odometry noise ``(σ_v, σ_ω)`` [m/s, rad/s]."""
    sv, sw = as_vector("odometry_sigma", odometry_sigma, 2)
    if sv <= 0 or sw <= 0:
        raise ValueError(f"odometry_sigma: expected (σ_v, σ_ω) > 0, got {(sv, sw)}")

    def g(x, u, dt):
        heading = x[2] + 0.5 * u[1] * dt
        return np.array([x[0] + u[0] * dt * np.cos(heading), x[1] + u[0] * dt * np.sin(heading), x[2] + u[1] * dt])

    def G(x, u, dt):
        heading = x[2] + 0.5 * u[1] * dt
        return np.array([[1.0, 0.0, -u[0] * dt * np.sin(heading)], [0.0, 1.0, u[0] * dt * np.cos(heading)],
                         [0.0, 0.0, 1.0]])

    def Q(dt):
        return np.diag([(sv * dt) ** 2, (sv * dt) ** 2, (sw * dt) ** 2])

    return Model(state_names=("x [m]", "y [m]", "yaw [rad]"), input_names=("v [m/s]", "omega [rad/s]"), g=g, G=G,
                 Q=Q, name="unicycle")


def scan_range_sensor(bearings, segments, max_range_m: float, sigma_m: float) -> Sensor:
    """The lidar's ranges along ``bearings`` (B,) [rad] in the map ``segments`` (S, 2, 2), clipped
    at ``max_range_m``, each with noise σ ``sigma_m``."""
    b = as_finite_array("bearings", bearings, ndim=1)
    seg = as_finite_array("segments", segments)
    if seg.ndim != 3 or seg.shape[1:] != (2, 2):
        raise ValueError(f"segments: expected wall segments of shape (S, 2, 2), got {seg.shape}")
    max_range, sigma = as_positive("max_range_m", max_range_m), as_positive("sigma_m", sigma_m)

    def h(x):
        return np.minimum(cast_rays(x[None, :2], x[2:3], b, seg)[0], max_range)

    def H(x):
        eps = np.array([1e-4, 1e-4, 1e-5])
        steps = x + np.diag(eps)[:, None, :] * np.array([1.0, -1.0])[None, :, None]  # (3, 2, 3): ± each axis
        r = np.minimum(cast_rays(steps.reshape(-1, 3)[:, :2], steps.reshape(-1, 3)[:, 2], b, seg), max_range)
        r = r.reshape(3, 2, b.size)
        return ((r[:, 0] - r[:, 1]) / (2.0 * eps[:, None])).T

    return Sensor(name="scan ranges", measurement_names=tuple(f"range {i} [m]" for i in range(b.size)), h=h, H=H,
                  R=sigma**2 * np.eye(b.size))
