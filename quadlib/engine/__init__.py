"""The compiled engine: every model's maths written once (:mod:`quadlib.kernels`), one loop per filter kind.

* :mod:`~quadlib.engine.kernel` — :class:`Kernel`, a compiled function with its parameters, which a
  :class:`~quadlib.model.Model` or :class:`~quadlib.model.Sensor` holds and Python calls as usual;
* :mod:`~quadlib.engine.dispatch` — the kernels the engine knows, and the switches that call them;
* :mod:`~quadlib.engine.loop` — the one loop over a log: schedule, χ² gates, timed resets;
* :mod:`~quadlib.engine.ekf` — its records, the EKF's steps (additive and error-state models) and the RTS pass;
* :mod:`~quadlib.engine.ukf` — the UKF's steps (additive and error-state models);
* :mod:`~quadlib.engine.runner` — which filters it can run, their arrays, the calls.

:func:`~quadlib.replay.run_filter` and :func:`~quadlib.replay.rts_smooth` choose between it and
their readable loops (``engine="auto"``) and record the choice in the run.
"""

from quadlib.engine.kernel import Kernel

__all__ = ["Kernel"]
