"""The models' and sensors' maths, written once, in the subset of Python that numba compiles.

Each function here is one piece of a model (``g``, ``G``, ``Q``, ``⊞``, ``⊟`` …) or of a sensor
(``h``, ``H``, a residual), its parameters passed last as one float array. A model factory binds
them into :class:`~quadlib.engine.kernel.Kernel` objects that a :class:`~quadlib.model.Model` or a
:class:`~quadlib.model.Sensor` holds; the readable filters call them from Python and the compiled
engine (:mod:`quadlib.engine`) from its loop, so both compute with the same code.

* :mod:`~quadlib.kernels.attitude` — attitude and gyro bias (multiplicative and additive), the
  gravity, heading and zero-rate sensors, and the shared pieces (identity, selections);
* :mod:`~quadlib.kernels.kesten` — Kesten's five attitude filters.
"""
