"""The models' and sensors' maths, written once, in the subset of Python that numba compiles.

Each function here is one piece of a model (``g``, ``G``, ``Q``, ``⊞``, ``⊟`` …) or of a sensor
(``h``, ``H``, a residual), its parameters passed last as one float array. A model factory binds
them into :class:`~quadlib.engine.kernel.Kernel` objects that a :class:`~quadlib.model.Model` or a
:class:`~quadlib.model.Sensor` holds; the readable filters call them from Python and the compiled
engine (:mod:`quadlib.engine`) from its loop, so both compute with the same code.

* :mod:`~quadlib.kernels.attitude` — attitude and gyro bias (multiplicative and additive), the
  gravity, heading and zero-rate sensors, and the shared pieces (identity, a linear measurement);
* :mod:`~quadlib.kernels.kesten` — Kesten's five attitude filters;
* :mod:`~quadlib.kernels.fixedwing`, :mod:`~quadlib.kernels.quad3d`, :mod:`~quadlib.kernels.ins` —
  the fixed-wing sensors, the 3D quadrotor and the strapdown INS;
* :mod:`~quadlib.kernels.linalg` — the small linear algebra they and the engine share.

The package's other compiled code lives here too, so that every module that imports numba is in
``quadlib/kernels`` or :mod:`quadlib.engine`: the low-passes of rest detection and of the
accelerometer (:mod:`~quadlib.kernels.lowpass`), the Euler-rate complementary filter
(:mod:`~quadlib.kernels.complementary`), the quadrotor's rigid body
(:mod:`~quadlib.kernels.vehicle`) and the lidar's ray caster (:mod:`~quadlib.kernels.lidar`).
"""

from __future__ import annotations

import functools

import numpy as np

__all__: list[str] = []  # internal: the models and the engine bind these


def called_from_python(loop):
    """``loop``, a compiled function that Python calls, with each array argument made C-contiguous
    and writable first. numba compiles one machine code per layout and read-only flag of its
    arguments: a column view or a read-only log would each cost another compile (15-20 s), on every
    fresh install, in whichever test or chapter met it first. ``py_func`` is the uncompiled loop."""

    @functools.wraps(loop)
    def call(*args):
        return loop(*(np.require(a, requirements="CW") if isinstance(a, np.ndarray) else a for a in args))

    call.py_func = loop.py_func
    return call
