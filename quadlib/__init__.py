"""quadlib: models, sensors, filter wrappers and metrics for the drone state-estimation notebooks.

Conventions (see notebook 00): earth frame NED, body frame FRD, SI units,
quaternions scalar first, noise given as standard deviations, every random
function takes a ``numpy.random.Generator``.
"""

from . import (
    averaging,
    data,
    histogram,
    metrics,
    models,
    montecarlo,
    plotting,
    reference,
    simulate,
    trajectories,
    validation,
)
from .display import show_source
from .filters import Innovation, LinearKF, ModelEKF, ModelUKF
from .model import Model, Sensor
from .replay import FilterRun, Measurements, SensorTrace, run_filter

__version__ = "0.1.0"

__all__ = [
    "FilterRun", "Innovation", "LinearKF", "Measurements", "Model", "ModelEKF", "ModelUKF",
    "Sensor", "SensorTrace", "averaging", "data", "histogram", "metrics", "models", "montecarlo",
    "plotting", "reference", "run_filter", "show_source", "simulate", "trajectories", "validation",
]
