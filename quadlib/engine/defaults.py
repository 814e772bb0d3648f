"""What the engine's loop (:mod:`quadlib.engine.template`) calls where a filter has no kernel of its own.

:mod:`quadlib.engine.build` binds these in a filter's compiled copy of the template for the roles
its model, sensors or sigma points leave empty: the plain ``⊟`` and weighted mean of an additive
UKF's state, and stand-ins for optional kernels whose steps the template's flags switch off (numba
drops those branches, so the stand-ins are never compiled). The model's ``g`` and ``Q`` and a
sensor's ``h`` have no default: here they are only names, so that the template imports.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from quadlib.engine.numerics import weighted_mean

__all__ = ["DEFAULTS"]


def _bound_by_build(*args):
    raise NotImplementedError("the template's kernels are bound by quadlib.engine.build in each filter's copy")


model_g = model_Q = sensor_h = sensor_H = sensor_residual = sensor_mean = _bound_by_build


@njit(cache=True)
def sigma_difference(a, b, p):
    """An additive state's ``a ⊟ b`` without a ``residual_x`` of its own: ``a − b``."""
    return a - b


@njit(cache=True)
def sigma_mean(Z, w, p):
    """An additive state's mean of sigma points without an ``x_mean_fn`` of its own: ``w Z``."""
    return weighted_mean(Z, w)


@njit(cache=True)
def model_G(x, u, dt, p):
    """No ``G`` (a UKF): never called."""
    return np.eye(x.shape[0])


@njit(cache=True)
def model_input_noise(u, dt, p):
    """No input noise: nothing added."""
    return False, np.zeros((0, 0))


@njit(cache=True)
def model_state_add(x, d, p):
    """An additive model: never called (``x + d``)."""
    return x + d


@njit(cache=True)
def model_residual_x(x1, x0, p):
    """An additive model: never called (``x₁ − x₀``)."""
    return x1 - x0


@njit(cache=True)
def model_add_jacobian(x, p):
    """No ``∂(x ⊞ δ)/∂δ``: never called."""
    return np.eye(x.shape[0])


@njit(cache=True)
def model_normalize(x, p):
    """No ``normalize``: never called."""
    return x


@njit(cache=True)
def model_normalize_jacobian(x, p):
    """No ``∂normalize/∂x``: never called."""
    return np.eye(x.shape[0])


DEFAULTS = {"G": model_G, "input_noise": model_input_noise, "state_add": model_state_add,
            "residual_x": model_residual_x, "add_jacobian": model_add_jacobian, "normalize": model_normalize,
            "normalize_jacobian": model_normalize_jacobian}
"""Model role → its stand-in, for a model without that kernel."""
