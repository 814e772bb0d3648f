"""The compiled engine: every model's maths written once (:mod:`quadlib.kernels`), each filter's loop
generated from its own kernels.

* :mod:`~quadlib.engine.kernel` — :class:`Kernel`, a compiled function with its parameters, which a
  :class:`~quadlib.model.Model` or :class:`~quadlib.model.Sensor` holds and Python calls as usual;
* :mod:`~quadlib.engine.template` — the loop over a log, written once: schedule, EKF and UKF steps,
  χ² gates, timed resets, the RTS pass;
* :mod:`~quadlib.engine.build` — a copy of the template per filter, its names bound to the filter's
  kernels, compiled on its first run and cached under a name made of the kernels' sources;
* :mod:`~quadlib.engine.numerics` — the arithmetic no kernel enters, compiled once for every filter;
* :mod:`~quadlib.engine.records` — the arrays the loop reads; :mod:`~quadlib.engine.runner` — which
  filters it can run, their records, the calls.

:func:`~quadlib.replay.run_filter` and :func:`~quadlib.replay.rts_smooth` choose between it and
their readable loops (``engine="auto"``) and record the choice in the run.
"""

from quadlib.engine.kernel import Kernel

__all__ = ["Kernel"]
