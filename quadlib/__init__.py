"""quadlib: models, sensors, filter wrappers and metrics for the drone state-estimation notebooks.

The core — :mod:`~quadlib.model` (``Model``, ``Sensor``), :mod:`~quadlib.filters` and
:mod:`~quadlib.model_filter` (the filterpy wrappers), :mod:`~quadlib.replay` (``run_filter``, the
one loop that drives every filter) and :mod:`~quadlib.stepper` (``FilterStepper``, its steps one at a
time, for a closed loop), :mod:`~quadlib.samples` and :mod:`~quadlib.imu` (what a log
holds: ``Samples``, ``Measurements``, ``ImuLog``, ``ImuNoise``) and :mod:`~quadlib.constants` —
sits at the top. Around it, one subpackage per concern:

``geometry``   quaternions, rotations, attitude from vector measurements
``sim``        model stepping, sensor sampling, trajectories, IMU samples
``analysis``   metrics, NEES/NIS, Monte Carlo
``teaching``   helpers that exist only for a chapter's explanation
``quad``       the quadrotor models, flights and the blog's pipeline
``attitude``   complementary filters, Kesten's attitude filters, the altitude filter
``fixedwing``  Salmony's fixed-wing model, flight and estimators
``nav``        the inertial navigation EKF, and the checks that align a real log's IMU and GPS
``control``    Kesten's controllers, a rigid-body quadrotor and the estimator-in-the-loop simulators
``perception`` a 2D lidar and ICP scan matching, for navigation without GPS
``data``       real sensor data (BROAD trials, PX4 logs)

Dependencies run one way: simulators and estimators depend on models and the core, never on
each other. Conventions (chapter 0): earth frame NED, body frame FRD, SI units, quaternions
scalar first, noise given as standard deviations, every random function takes a
``numpy.random.Generator``.
"""

from quadlib import numba_cache  # noqa: F401  (first: it clears a stale numba cache before anything loads it)
from quadlib.filters import LinearKF, ModelEKF, ModelUKF
from quadlib.model import Model, Sensor
from quadlib.model_filter import Innovation, ModelFilter
from quadlib.replay import FilterDivergedError, FilterRun, SensorTrace, rts_smooth, run_filter
from quadlib.samples import Measurements, Samples
from quadlib.stepper import FilterStepper, Sample

__version__ = "0.1.0"

__all__ = ["FilterDivergedError", "FilterRun", "FilterStepper", "Innovation", "LinearKF", "Measurements", "Model",
           "ModelEKF", "ModelFilter", "ModelUKF", "Sample", "Samples", "Sensor", "SensorTrace", "estimate_ins",
           "estimate_orientation", "rts_smooth", "run_filter"]

# The two one-call estimators, for engineers: imported on first use, so that ``import quadlib``
# stays light (they pull in the attitude and navigation subpackages).
_ESTIMATORS = {"estimate_orientation": "quadlib.attitude", "estimate_ins": "quadlib.nav"}


def __getattr__(name: str):
    if name in _ESTIMATORS:
        import importlib

        return getattr(importlib.import_module(_ESTIMATORS[name]), name)
    raise AttributeError(f"module 'quadlib' has no attribute {name!r}")
