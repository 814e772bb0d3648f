"""What the closed loops of :mod:`quadlib.control.closed_loop` are asked to follow: a
:class:`Reference` (height, climb rate, attitude and body rates) at each time, from Kesten's two
test references, the altitude step of Fig. 5.3 and the attitude wave of Fig. 5.4.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from quadlib.geometry.quaternion import as_unit_quaternions
from quadlib.kernels.quaternion import conjugate, exp_rotvec, multiply, rotvec
from quadlib.validation import as_finite_array, as_finite_number, as_positive, as_vector

__all__ = ["Reference", "altitude_step", "attitude_wave"]


@dataclass(frozen=True)
class Reference:
    """What the controllers are asked to follow at time ``t``: height ``s`` [m, up], climb rate
    ``v`` [m/s], attitude ``q_nb`` and body rates ``ω`` [rad/s]."""

    s: float
    v: float
    q_nb: np.ndarray
    omega: np.ndarray

    def __post_init__(self):
        for name in ("s", "v"):
            object.__setattr__(self, name, as_finite_number(f"Reference.{name}", getattr(self, name)))
        q = as_unit_quaternions("Reference.q_nb", self.q_nb)
        if q.shape != (4,):
            raise ValueError(f"Reference.q_nb: expected one quaternion of shape (4,), got {q.shape}")
        object.__setattr__(self, "q_nb", q)
        object.__setattr__(self, "omega", as_vector("Reference.omega", self.omega, 3))


def altitude_step(t_step_s: float = 5.0, height_m: float = 2.0, start_m: float = 1.0) -> Callable[[float], Reference]:
    """Kesten's Fig. 5.3 reference: hover at ``start_m``, then a step of ``height_m`` at ``t_step_s``,
    level and facing north throughout."""
    t_step_s, height_m, start_m = (as_finite_number(n, v) for n, v in
                                   (("t_step_s", t_step_s), ("height_m", height_m), ("start_m", start_m)))
    level, still = np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3)
    before, after = Reference(start_m, 0.0, level, still), Reference(start_m + height_m, 0.0, level, still)
    return lambda t: after if t >= t_step_s else before


def attitude_wave(amplitudes_rad=(0.15, 0.1, 0.3), periods_s=(8.0, 5.0, 12.0), height_m: float = 1.0,
                  step_at_s: float | None = None, step_rad: float = 0.1) -> Callable[[float], Reference]:
    """A reference attitude for Kesten's Fig. 5.4: each orientation-vector component a sine
    ``θᵢ = aᵢ sin(2π t / Tᵢ)`` (``q = exp(θ)``), with its body rates, at a constant height; with
    ``step_at_s``, the roll component steps by ``step_rad`` there (the rate reference does not)."""
    a, periods = as_finite_array("amplitudes_rad", amplitudes_rad), as_finite_array("periods_s", periods_s)
    if a.shape != (3,) or periods.shape != (3,) or not np.all(periods > 0):
        raise ValueError(f"amplitudes_rad, periods_s: expected three finite amplitudes and three positive periods, "
                         f"got {amplitudes_rad!r}, {periods_s!r}")
    w = 2.0 * np.pi / periods
    height = as_positive("height_m", height_m)
    step_rad = as_finite_number("step_rad", step_rad)
    if step_at_s is not None:
        step_at_s = as_finite_number("step_at_s", step_at_s)

    def theta(t):
        th = a * np.sin(w * t)
        if step_at_s is not None and t >= step_at_s:
            th = th + np.array([step_rad, 0.0, 0.0])
        return th

    def reference(t):
        q = exp_rotvec(theta(t))
        h = 1e-4
        q_next = exp_rotvec(a * np.sin(w * (t + h)) + (theta(t) - a * np.sin(w * t)))
        omega = rotvec(multiply(conjugate(q), q_next)) / h
        return Reference(height, 0.0, q, omega)

    return reference
