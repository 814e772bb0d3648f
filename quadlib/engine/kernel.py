"""A model's or a sensor's function written once, in numba, and held by a Model or a Sensor.

A :class:`Kernel` is what a :class:`~quadlib.model.Model` field (``g``, ``G``, ``Q`` …) or a
:class:`~quadlib.model.Sensor` field (``h``, ``H``, ``residual``) holds when the function is compiled
with numba — one of :mod:`quadlib.kernels`, or a user's own ``@njit`` function: the numba function
and the numbers it needs (a noise density, a reference vector), bound together. Called from
Python — by the readable filters, by a chapter — it behaves like the plain function the field
documents (``g(x, u, dt)``, ``h(x)`` or ``h(x, c)`` …). The compiled engine
(:mod:`quadlib.engine.template`) reads ``function`` and ``params`` instead and calls the same numba
function inside its loop: one implementation, two callers.

Every kernel takes its parameters last, as one float array: ``g(x, u, dt, p)``, ``G(x, u, dt, p)``,
``Q(dt, p)``, ``input_noise(u, dt, p) -> (added, M)``, ``state_add(x, d, p)``,
``residual_x(x1, x0, p)``, ``add_jacobian(x, p)``, ``normalize(x, p)``,
``normalize_jacobian(x, p)``; a sensor's ``h(x, c, p)``, ``H(x, c, p)``, ``residual(z, z_hat, p)``
(``c`` the sample's context, empty for a sensor without one) and ``mean(Z, weights, p)`` (a UKF's
weighted mean of sigma points, which also serves as ModelUKF's ``x_mean_fn``). The engine passes each kernel its
parameters padded with zeros to the longest of its model's, so a kernel reads its sizes from its
parameters, never from their length.
"""

from __future__ import annotations

import numpy as np

from quadlib.kernels.attitude import linear_map, linear_map_H

__all__ = ["MODEL_ROLES", "SENSOR_ROLES", "Kernel", "linear_kernels"]

MODEL_ROLES = ("g", "G", "Q", "input_noise", "state_add", "residual_x", "add_jacobian", "normalize",
               "normalize_jacobian")
SENSOR_ROLES = ("h", "H", "residual", "mean")
_NO_CONTEXT = np.zeros(0)


_F64 = np.dtype(np.float64)


def _arg(a):
    """One argument as numba's one compiled version expects it: a C-contiguous, writable float64
    array (a view, a read-only log or a list would each cost another compile), or a float."""
    if type(a) is np.ndarray:  # the readable filters call a kernel per sigma point: the common case first
        flags = a.flags
        if a.dtype == _F64 and flags.c_contiguous and flags.writeable:
            return a
    if isinstance(a, np.ndarray):
        return np.require(a, dtype=np.float64, requirements="CW")
    if isinstance(a, (list, tuple)):
        return np.array(a, dtype=np.float64)
    return float(a)


class Kernel:
    """``function`` (a numba function of :mod:`quadlib.kernels`) with its parameters ``params`` bound.

    Parameters
    ----------
    role : str
        Which field it fills: one of :data:`MODEL_ROLES` or :data:`SENSOR_ROLES`.
    function : numba function
        Takes the role's arguments, then ``params``.
    params : array_like of float
        The numbers the function needs besides its arguments (copied).
    context : bool
        For a sensor's ``h`` and ``H``: True when the sensor has ``context_names`` (then it is
        called ``h(x, c)``), False for ``h(x)``.
    """

    __slots__ = ("role", "function", "params", "context", "_bare")

    def __init__(self, role: str, function, params=(), context: bool = False):
        if role not in MODEL_ROLES + SENSOR_ROLES:
            raise ValueError(f"role: expected one of {MODEL_ROLES + SENSOR_ROLES}, got {role!r}")
        if not callable(function):
            raise TypeError(f"function: expected a numba function, got {function!r}")
        self.role, self.function, self.context = role, function, bool(context)
        self.params = np.array(params, dtype=np.float64).reshape(-1)
        self._bare = role in ("h", "H") and not self.context  # called h(x): the empty context added

    def __call__(self, *args):
        if self._bare:
            if len(args) != 1:
                raise TypeError(f"{self.function.__name__}: expected h(x) (the sensor has no context), "
                                f"got {len(args)} arguments")
            args = (args[0], _NO_CONTEXT)
        out = self.function(*map(_arg, args), self.params)
        if self.role == "input_noise":  # (added, M): None when the input adds nothing, as the field documents
            return out[1] if out[0] else None
        return out

    def __repr__(self) -> str:
        return f"Kernel({self.role!r}, {self.function.__name__}, params={self.params.tolist()})"


def linear_kernels(A) -> tuple[Kernel, Kernel]:
    """A linear sensor's ``h(x) = A x`` and ``H = A`` as kernels: states picked (GPS, a gyro's bias),
    turned in sign (the barometer's height ``−p_d``) or combined."""
    A = np.asarray(A, dtype=float)
    p = np.r_[A.shape, A.ravel()]
    return Kernel("h", linear_map, p), Kernel("H", linear_map_H, p)
