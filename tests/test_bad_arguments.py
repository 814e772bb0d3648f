"""Bad arguments across the public API, property-based.

Every probed callable has a valid call below and a *kind* for each argument; hypothesis draws
values that are wrong for that kind (a non-positive or non-finite scale, a probability outside
(0, 1), a vector of the wrong length, NaN in a quaternion, a time axis that goes back, an object
of the wrong type) and puts one of them in place of one argument. The call must raise
``ValueError`` or ``TypeError`` whose message names the argument as the caller wrote it, says
what was expected and shows what it got. A call that returns is a silent failure; another
exception, or a message without those three parts, is an unhelpful one.

``test_every_public_callable_is_probed_or_listed`` keeps the registry honest: a public callable
is either probed here or listed in ``NOT_YET_PROBED`` (44 of 174 are probed so far; the list
shrinks as probes are added, and a new public name must join one or the other).
"""

from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass, field

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from quadlib import LinearKF, Model, ModelEKF, ModelUKF, Samples, Sensor, run_filter
from quadlib.analysis import metrics
from quadlib.attitude import (
    AttitudeNoise,
    OrientationParams,
    altitude_model,
    baro_altitude_sensor,
    estimate_orientation,
    gravity_sensor,
    heading_sensor,
    qkf,
    random_rotation,
    run_attitude_filter,
    with_spin,
)
from quadlib.constants import earth_field_ned
from quadlib.data import data_path, load_broad_trial
from quadlib.fixedwing import (
    FixedWingNoise,
    aileron_roll,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    lowpass2,
)
from quadlib.geometry import quaternion, rotations
from quadlib.imu import ImuLog, ImuNoise
from quadlib.samples import Measurements
from quadlib.sim import imu_samples, min_jerk

NAN, INF = float("nan"), float("inf")
WRONG_TYPE = st.sampled_from(["text", None, object(), {"a": 1}])

BAD = {
    "positive": st.one_of(st.floats(max_value=0.0, allow_nan=False), st.sampled_from([NAN, INF, -INF, "1.0"])),
    "finite": st.sampled_from([NAN, INF, -INF, "1.0"]),
    "probability": st.one_of(st.floats(max_value=0.0, allow_nan=False),
                             st.floats(min_value=1.0, allow_nan=False), st.sampled_from([NAN, "0.5"])),
    "count": st.one_of(st.integers(max_value=0), st.sampled_from([1.5, NAN, "3", True])),
    "vector3": st.one_of(st.sampled_from([[1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [NAN, 0.0, 1.0], [INF, 0.0, 1.0],
                                          "abc", None])),
    "quaternion": st.sampled_from([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0], [NAN, 0.0, 0.0, 0.0],
                                   [1.0, INF, 0.0, 0.0], "wxyz", None]),
    "unit quaternion": st.sampled_from([[0.0, 0.0, 0.0, 0.0], [0.5, 0.5, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0],
                                        [NAN, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], "wxyz"]),
    "nonzero quaternion": st.sampled_from([[0.0, 0.0, 0.0, 0.0], [NAN, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0], "wxyz", None]),
    "matrix3": st.sampled_from([np.eye(2), np.full((3, 3), NAN), np.eye(4), "R", None]),
    "times": st.sampled_from([[0.0, 0.2, 0.1], [0.0, NAN, 0.2], [[0.0, 0.1]], "t", None]),
    "rng": st.sampled_from(["seed", 1.5, [1, 2], object()]),
    "state2": st.sampled_from([[1.0], [1.0, 2.0, 3.0], [NAN, 0.0], [INF, 0.0], "x", None]),
    "angles or NaN": st.sampled_from([INF, -INF, [0.0, INF], "a", None]),
}


def _wrong_type(kind: type) -> st.SearchStrategy:
    return st.sampled_from([1.0, "text", None, [1.0, 2.0], object()]).filter(lambda v: not isinstance(v, kind))


@dataclass
class Probe:
    """A valid call of ``func`` (``args()`` builds fresh keyword arguments) and each argument's kind."""

    func: object
    args: object
    kinds: dict = field(default_factory=dict)


def _motion():
    return random_rotation(2.0, 50.0, np.random.default_rng(0))


def _imu_log(n=100):
    noise = AttitudeNoise()
    return imu_samples(random_rotation((n - 1) / 50.0, 50.0, np.random.default_rng(0)), noise,
                       np.random.default_rng(1), field_n=noise.field_n)


def _cv_model():
    return Model(("p", "v"), ("a",), g=lambda x, u, dt: np.array([x[0] + dt * x[1], x[1] + dt * u[0]]),
                 G=lambda x, u, dt: np.array([[1.0, dt], [0.0, 1.0]]),
                 B=lambda x, u, dt: np.array([[0.0], [dt]]), Q=lambda dt: np.eye(2) * dt, name="cv")


def _position_sensor():
    return Sensor("pos", ("p",), h=lambda x: x[:1], H=lambda x: np.array([[1.0, 0.0]]), R=[[0.1]])


def _run_filter_args():
    t = np.arange(5) * 0.1
    return dict(filt=ModelEKF(_cv_model(), [0.0, 0.0], np.eye(2), 0.1), t=t, u=np.zeros((5, 1)),
                measurements=[Measurements(_position_sensor(), t, np.zeros((5, 1)))], gate_probability=0.99)


PROBES = [
    # the core
    Probe(ModelEKF, lambda: dict(model=_cv_model(), x0=[0.0, 0.0], P0=np.eye(2), dt=0.1),
          {"model": _wrong_type(Model), "x0": BAD["state2"], "P0": st.sampled_from(
              [-np.eye(2), np.zeros((2, 2)), np.eye(3), np.full((2, 2), NAN), "P"]), "dt": BAD["positive"]}),
    Probe(ModelUKF, lambda: dict(model=_cv_model(), x0=[0.0, 0.0], P0=np.eye(2), dt=0.1),
          {"model": _wrong_type(Model), "x0": BAD["state2"], "dt": BAD["positive"]}),
    Probe(LinearKF, lambda: dict(model=_cv_model(), x0=[0.0, 0.0], P0=np.eye(2), dt=0.1),
          {"model": _wrong_type(Model), "x0": BAD["state2"], "dt": BAD["positive"]}),
    Probe(run_filter, _run_filter_args,
          {"filt": WRONG_TYPE, "t": BAD["times"], "u": st.sampled_from([np.zeros((4, 1)), np.zeros((5, 2)), "u"]),
           "measurements": st.sampled_from([[1.0], ["gps"], 3.0]), "gate_probability": BAD["probability"]}),
    Probe(Samples, lambda: dict(t=[0.0, 0.1], z=[[1.0], [2.0]]),
          {"t": BAD["times"], "z": st.sampled_from([[[1.0]], [1.0, 2.0, 3.0], "z", [[INF], [0.0]]])}),
    Probe(Measurements, lambda: dict(sensor=_position_sensor(), t=[0.0, 0.1], z=[[1.0], [2.0]]),
          {"sensor": WRONG_TYPE, "t": BAD["times"], "z": st.sampled_from([[[1.0]], [[1.0, 2.0], [1.0, 2.0]], "z"])}),
    Probe(ImuLog, lambda: dict(t=[0.0, 0.1], gyro=np.zeros((2, 3)), accel=np.zeros((2, 3))),
          {"t": BAD["times"], "gyro": st.sampled_from([np.zeros((2, 2)), np.full((2, 3), INF), "g", None]),
           "accel": st.sampled_from([np.zeros((3, 3)), np.full((2, 3), INF), "a", None])}),
    Probe(ImuNoise, lambda: dict(gyro_range_rad_s=30.0), {"gyro_range_rad_s": BAD["positive"]}),
    # geometry
    Probe(quaternion.quat_multiply, lambda: dict(p=[1.0, 0, 0, 0], q=[1.0, 0, 0, 0]),
          {"p": BAD["quaternion"], "q": BAD["quaternion"]}),
    Probe(quaternion.quat_normalize, lambda: dict(q=[1.0, 0, 0, 0]),
          {"q": st.sampled_from([[0.0, 0.0, 0.0, 0.0], [NAN, 0.0, 0.0, 0.0], [1.0, 0.0], "q"])}),
    Probe(quaternion.quat_to_dcm, lambda: dict(q=[1.0, 0, 0, 0]), {"q": BAD["unit quaternion"]}),
    Probe(quaternion.quat_to_euler, lambda: dict(q=[1.0, 0, 0, 0]), {"q": BAD["unit quaternion"]}),
    Probe(quaternion.quat_to_rotvec, lambda: dict(q=[1.0, 0, 0, 0]), {"q": BAD["unit quaternion"]}),
    Probe(quaternion.quat_rotate, lambda: dict(q=[1.0, 0, 0, 0], v=[1.0, 0, 0]),
          {"q": BAD["unit quaternion"], "v": BAD["vector3"]}),
    Probe(quaternion.quat_from_rotvec, lambda: dict(v=[0.1, 0, 0]), {"v": BAD["vector3"]}),
    Probe(quaternion.quat_from_dcm, lambda: dict(R=np.eye(3)),
          {"R": st.sampled_from([np.diag([1.0, 1.0, -1.0]), 2 * np.eye(3), np.eye(2), np.full((3, 3), NAN), "R"])}),
    Probe(quaternion.quat_from_euler, lambda: dict(roll=0.1, pitch=0.2, yaw=0.3),
          {"roll": BAD["finite"], "pitch": BAD["finite"], "yaw": BAD["finite"]}),
    Probe(quaternion.integrate_body_rate, lambda: dict(q=[1.0, 0, 0, 0], omega_b=[0.1, 0, 0], dt=0.01),
          {"q": BAD["nonzero quaternion"], "omega_b": BAD["vector3"], "dt": BAD["positive"]}),
    Probe(quaternion.body_rates_between, lambda: dict(q_nb=[[1.0, 0, 0, 0], [1.0, 0, 0, 0]], dt=0.01),
          {"q_nb": st.sampled_from([[[1.0, 0, 0]], [[NAN, 0, 0, 0], [1.0, 0, 0, 0]], "q"]), "dt": BAD["positive"]}),
    Probe(quaternion.body_vector, lambda: dict(q=[1.0, 0, 0, 0], v_n=[1.0, 0, 0]),
          {"q": BAD["quaternion"], "v_n": BAD["vector3"]}),
    Probe(quaternion.vector_jacobian, lambda: dict(q=[1.0, 0, 0, 0], v_n=[1.0, 0, 0]),
          {"q": BAD["quaternion"], "v_n": BAD["vector3"]}),
    Probe(rotations.accel_tilt, lambda: dict(f_b=[0.0, 0.0, -9.8]),  # NaN marks a missing sample
          {"f_b": BAD["vector3"].filter(lambda v: not (isinstance(v, list) and NAN in v))}),
    Probe(rotations.euler_to_dcm, lambda: dict(roll=0.1, pitch=0.2, yaw=0.3),
          {"roll": BAD["finite"], "pitch": BAD["finite"], "yaw": BAD["finite"]}),
    Probe(rotations.dcm_to_euler, lambda: dict(R=np.eye(3)), {"R": BAD["matrix3"]}),
    Probe(rotations.wrap_angle, lambda: dict(a=1.0), {"a": BAD["angles or NaN"]}),
    Probe(rotations.mag_heading, lambda: dict(m_b=[0.2, 0.0, 0.4], roll=0.0, pitch=0.0),
          {"m_b": BAD["vector3"], "roll": BAD["finite"], "pitch": BAD["finite"], "declination_rad": BAD["finite"]}),
    # analysis
    Probe(metrics.attitude_error, lambda: dict(q_estimate=[1.0, 0, 0, 0], q_truth=[1.0, 0, 0, 0]),
          {"q_estimate": BAD["unit quaternion"], "q_truth": BAD["unit quaternion"]}),
    Probe(metrics.angle_error, lambda: dict(estimate=[0.1], truth=[0.2]),
          {"estimate": st.sampled_from([[INF], "x", [0.1, 0.2, 0.3]]), "truth": BAD["angles or NaN"]}),
    Probe(metrics.rmse, lambda: dict(error=[0.1, 0.2]), {"error": st.sampled_from([[INF, 0.1], "e", None])}),
    # sensors, models and simulators
    Probe(imu_samples, lambda: dict(motion=_motion(), noise=AttitudeNoise(), rng=np.random.default_rng(0)),
          {"motion": WRONG_TYPE, "noise": _wrong_type(ImuNoise), "rng": BAD["rng"],
           "field_n": BAD["vector3"].filter(lambda v: v is not None),
           "mag_every": BAD["count"], "accel_every": BAD["count"]}),
    Probe(random_rotation, lambda: dict(duration_s=1.0, rate_hz=50.0, rng=np.random.default_rng(0)),
          {"duration_s": BAD["positive"], "rate_hz": BAD["positive"], "rng": BAD["rng"],
           "rms_rate_rad_s": BAD["positive"], "n_terms": BAD["count"]}),
    Probe(with_spin, lambda: dict(motion=_motion(), start_s=0.5, duration_s=0.5, rate_rad_s=10.0),
          {"motion": WRONG_TYPE, "start_s": st.sampled_from([-5.0, 100.0, NAN, "0"]), "duration_s": BAD["positive"],
           "rate_rad_s": BAD["finite"]}),
    Probe(min_jerk, lambda: dict(s=[0.0, 0.5, 1.0]), {"s": st.sampled_from([[NAN], "s", None])}),
    Probe(fixedwing_flight, lambda: dict(rate_hz=25.0), {"rate_hz": BAD["positive"], "airspeed_m_s": BAD["positive"]}),
    Probe(aileron_roll, lambda: dict(flight=fixedwing_flight(rate_hz=10.0), start_s=10.0, rate_rad_s=10.0),
          {"flight": WRONG_TYPE, "start_s": st.sampled_from([-1.0, 500.0, NAN, "1"]), "rate_rad_s": BAD["positive"],
           "turns": BAD["count"]}),
    Probe(lowpass2, lambda: dict(x=np.zeros((5, 3)), cutoff_hz=2.0, dt=0.02),
          {"x": st.sampled_from(["x", None]), "cutoff_hz": BAD["positive"], "dt": BAD["positive"]}),
    Probe(altitude_model, lambda: dict(accel_sigma_m_s2=0.06, gravity_weight=1e-4),
          {"accel_sigma_m_s2": BAD["positive"], "gravity_weight": BAD["probability"],
           "accel_range_m_s2": BAD["positive"]}),
    Probe(baro_altitude_sensor, lambda: dict(sigma_m=0.4), {"sigma_m": BAD["positive"], "rate_hz": BAD["positive"]}),
    Probe(gravity_sensor, lambda: dict(sigma_m_s2=1.0), {"sigma_m_s2": BAD["positive"]}),
    Probe(heading_sensor, lambda: dict(sigma_rad=0.1), {"sigma_rad": BAD["positive"]}),
    Probe(earth_field_ned, lambda: dict(strength=0.5, inclination_rad=1.0),
          {"strength": BAD["positive"], "inclination_rad": BAD["finite"], "declination_rad": BAD["finite"]}),
    # estimators
    Probe(qkf, lambda: dict(noise=AttitudeNoise()),
          {"noise": _wrong_type(AttitudeNoise), "sigma0_rad": BAD["positive"], "checks": WRONG_TYPE}),
    Probe(run_attitude_filter, lambda: dict(filt=qkf(AttitudeNoise()), log=_imu_log()),
          {"filt": WRONG_TYPE, "log": WRONG_TYPE, "q0": BAD["quaternion"]}),
    Probe(estimate_orientation, lambda: dict(log=_imu_log(), params=OrientationParams()),
          {"log": WRONG_TYPE, "params": _wrong_type(OrientationParams), "declination_rad": BAD["finite"]}),
    Probe(estimate_fixedwing_attitude,
          lambda: dict(log=fixedwing_samples(fixedwing_flight(rate_hz=10.0), FixedWingNoise(),
                                             np.random.default_rng(0)).slice(0, 60), noise=FixedWingNoise()),
          {"log": WRONG_TYPE, "noise": _wrong_type(FixedWingNoise), "filter_factory": WRONG_TYPE,
           "declination_rad": BAD["finite"], "inclination_rad": BAD["finite"]}),
    # data
    Probe(data_path, lambda: dict(name="broad/trials.json"),
          {"name": st.sampled_from(["../../etc/passwd", "", None, 3.0, "broad/no_such_file.hdf5"])}),
    Probe(load_broad_trial, lambda: dict(name="02_undisturbed_slow_rotation_A"),
          {"name": st.sampled_from(["99_no_such_trial", "", None, 3.0])}),
]

NOT_YET_PROBED = frozenset({
    "AbsoluteAttitude", "AttitudeNoise", "AttitudeRun", "BodyMotion", "BroadTrial", "FilterRun",
    "FixedWingFlight", "FixedWingNoise", "FixedWingTuning", "Flight3D", "Innovation", "KestenFilter", "Model",
    "ModelFilter", "Moments", "MonteCarloRuns", "OrientationParams", "Quad3DTuning", "Run3D", "Sensor",
    "SensorChecks", "SensorNoise3D", "SensorTrace", "accel_jacobian", "accel_model", "airspeed_from_pressure",
    "altitude_from_pressure", "angle_rmse", "animate_quad2d", "animation_html", "as_unit_quaternions",
    "attitude_bias_model", "attitude_from_accel_mag", "attitude_rmse", "average_geodesic", "average_quaternion",
    "average_rotvec", "baro_samples", "batch_mean", "belief_mean_std", "blend_weight", "broad_errors",
    "broad_trial_names", "chi2_interval", "complementary_attitude", "dcm_dyaw", "error_state_ukf",
    "estimate_quad3d", "euler_rate_complementary", "euler_rate_matrix", "exponential_average", "figure_eight",
    "fixedwing_A", "fixedwing_accel_sensor", "fixedwing_f", "fixedwing_mag_sensor", "fixedwing_measurements",
    "fixedwing_model", "fixedwing_samples", "flight_from_path", "fraction_inside", "gaussian_belief",
    "gaussian_kernel", "gaussian_likelihood", "gps_samples", "gyro_step", "gyro_step_jacobian", "half_average",
    "height_model", "importance_posterior", "imu_inputs", "initial_state", "integrate_body_rate_linear",
    "linear_complementary", "mag_field_samples", "mag_jacobian", "mag_model", "mag_yaw_samples",
    "multiplicative_ekf", "nees", "nis", "nonlinear_complementary", "normalize_attitude",
    "normalize_attitude_jacobian", "piecewise_constant", "plausible_accel", "plausible_mag", "plot_consistency",
    "plot_estimate", "plot_innovations", "pressure_from_altitude", "propagate_samples", "qf", "quad1d_model",
    "quad1d_range_sensor", "quad2d_geometry", "quad2d_model", "quad2d_range_sensor", "quad3d_baro_sensor",
    "quad3d_ekf", "quad3d_gps_sensor", "quad3d_mag_sensor", "quad3d_model", "quad3d_ukf_options",
    "quat_canonical", "quat_conjugate", "quaternion_rate_matrix", "range_sensor", "recursive_mean",
    "run3d_measurements", "run_monte_carlo", "salmony_ekf", "sample_sensor", "search_dirs", "settling_time",
    "show_source", "simple_pipeline", "simulate_model", "simulate_run3d", "specific_force_at_rest",
    "square_course", "step_profile", "tilted_range_sensor", "tovkf", "tqf", "tqkf", "uniform_grid",
    "vertical_specific_force", "with_dropouts", "with_outliers"
})


def _public_callables():
    out = {}
    for module_name in ("quadlib", "quadlib.geometry", "quadlib.sim", "quadlib.analysis", "quadlib.teaching",
                        "quadlib.quad", "quadlib.attitude", "quadlib.fixedwing", "quadlib.data"):
        module = importlib.import_module(module_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if callable(obj) and not (inspect.isclass(obj) and issubclass(obj, BaseException)):
                out[f"{module_name}.{name}"] = obj
    return out


CASES = [(probe, arg) for probe in PROBES for arg in probe.kinds]


@pytest.mark.parametrize(("probe", "arg"), CASES, ids=[f"{p.func.__name__}-{a}" for p, a in CASES])
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_a_bad_argument_gets_a_named_error(probe, arg, data):
    kwargs = probe.args()
    value = data.draw(probe.kinds[arg], label=arg)
    kwargs[arg] = value
    try:
        probe.func(**kwargs)
    except (ValueError, TypeError) as err:
        message = str(err)
        assert arg in message, f"the message does not name {arg!r}: {message}"
        assert "expected" in message and "got" in message, f"no expectation or no value given: {message}"
    else:
        pytest.fail(f"{probe.func.__name__}({arg}={value!r}) returned without an error")


def test_every_public_callable_is_probed_or_listed():
    public = _public_callables()
    probed = {id(p.func) for p in PROBES}
    unprobed = {name.rsplit(".", 1)[1] for name, obj in public.items() if id(obj) not in probed}
    assert unprobed == NOT_YET_PROBED, (f"probe these or list them: {sorted(unprobed - NOT_YET_PROBED)}; "
                                        f"probed now, remove from the list: {sorted(NOT_YET_PROBED - unprobed)}")
