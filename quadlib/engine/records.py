"""The records the engine's loop reads: a filter's sensors, its log's samples and a UKF's sigma points.

:mod:`quadlib.engine.runner` packs them from a filter and its measurements; the compiled copy of
:mod:`quadlib.engine.template` reads them. A model's parameters are one array ``(9, m)``, a row per
role of :data:`~quadlib.engine.kernel.MODEL_ROLES`, each padded with zeros to the longest.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["Samples", "SensorArrays", "SigmaArrays"]


class SensorArrays(NamedTuple):
    """The sensors, one row each: the parameters of ``h``, ``H``, the residual and the mean
    (``params (S, 4, m)``); ``dim_z``, ``dim_c``; ``R (S, k, k)``; each row's group (``group (S, k)``)
    and ``n_groups``; the χ² threshold of each group (``gates (S, g)``, ``≤ 0``: not gated);
    ``reset_after_s`` (``≤ 0``: never); ``corrected (S, p)``, the gain's rows kept; for a reset that
    needs the refused readings to agree, ``whiten (S, k, k)`` and the normal quantile ``agree_z (S,)``
    of :func:`~quadlib.model_filter.agreement_test` (NaN: not needed)."""

    params: np.ndarray
    dim_z: np.ndarray
    dim_c: np.ndarray
    R: np.ndarray
    group: np.ndarray
    n_groups: np.ndarray
    gates: np.ndarray
    reset_after_s: np.ndarray
    corrected: np.ndarray
    whiten: np.ndarray
    agree_z: np.ndarray


class Samples(NamedTuple):
    """Each sensor's samples, one row of each array per sensor (padded): times ``t (S, K)``, values
    ``z (S, K, k)`` and contexts ``c (S, K, c)``; and the ``count[s]`` samples it applies, in order —
    sample ``use[s, i]`` after the predict of step ``step[s, i]`` (missing and repeated ones left out)."""

    t: np.ndarray
    z: np.ndarray
    c: np.ndarray
    use: np.ndarray
    step: np.ndarray
    count: np.ndarray


class SigmaArrays(NamedTuple):
    """A UKF's sigma points: the weights ``Wm``, ``Wc``, ``scale = λ + n`` of ``U = chol(scale · P)``,
    and the parameters ``params (2, m)`` of an additive state's ``⊟`` and mean."""

    Wm: np.ndarray
    Wc: np.ndarray
    scale: float
    params: np.ndarray
