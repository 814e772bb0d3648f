"""The 3D quadrotor EKF and UKF on the compiled engine give what the readable ones (ModelEKF and
ModelUKF driven by run_filter) give: the same states, covariances and sensor traces, to 1e-10 — with
samples between the steps, a GPS outage, magnetometer dropouts, a repeated timestamp, held input
rows, a heading that crosses ±180°, a start far from the truth, gate rejections and resets, and a
model a user changed."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, ModelUKF, run_filter
from quadlib.engine import Kernel
from quadlib.kernels import quad3d as quad3d_maths
from quadlib.quad.estimate import Quad3DParams, estimate_quad3d, quad3d_ekf, quad3d_ukf
from quadlib.quad.flight import SensorNoise3D, square_course
from quadlib.quad.quad3d import quad3d_ukf_options
from quadlib.quad.scenario import simulate_run3d
from quadlib.replay import FilterDivergedError
from quadlib.samples import Samples

RUN = simulate_run3d(square_course(leg_s=4.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(8), decimate=10,
                     tau=5.0)


def _faulty():
    """RUN with a 3 s GPS outage, 10 % of the headings missing, one heading repeated at the same time
    (dropped), 5 % of the input rows missing (held), and a start 3 m and 40° off."""
    rng = np.random.default_rng(9)
    gps_z = RUN.gps.z.copy()
    gps_z[(RUN.gps.t > 6.0) & (RUN.gps.t < 9.0)] = np.nan
    mag_t, mag_z = RUN.mag.t.copy(), RUN.mag.z.copy()
    mag_z[rng.random(mag_t.size) < 0.1] = np.nan
    mag_t[501] = mag_t[500]
    u = RUN.u.copy()
    u[1:][rng.random(u.shape[0] - 1) < 0.05] = np.nan
    x0 = RUN.truth[0] + np.r_[3.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.radians(40.0)]
    return u, Samples(RUN.gps.t, gps_z), Samples(mag_t, mag_z), x0


U, GPS, MAG, X0 = _faulty()
CASES = {"clean": (RUN.u, RUN.gps, RUN.mag, RUN.truth[0]), "faults": (U, GPS, MAG, X0)}
GATED = Quad3DParams(gate_probability=0.999)


@pytest.mark.parametrize("factory", [quad3d_ekf, quad3d_ukf], ids=["EKF", "UKF"])
@pytest.mark.parametrize("case", list(CASES))
def test_the_compiled_loop_equals_the_readable_one(case, factory, assert_same_run):
    u, gps, mag, x0 = CASES[case]
    assert_same_run(estimate_quad3d(RUN.t, u, gps, mag, x0, filter_factory=factory),
                     estimate_quad3d(RUN.t, u, gps, mag, x0, filter_factory=factory, compiled=False))


def test_the_cases_reach_every_branch():
    """The comparisons above are only worth something if each branch happened in them."""
    run = estimate_quad3d(RUN.t, U, GPS, MAG, X0)
    assert run.held_input.sum() > 30
    assert run.sensors["gps"].missing.sum() >= 25 and run.sensors["mag"].missing.sum() > 100
    assert run.sensors["mag"].duplicate.sum() == 1
    assert np.searchsorted(RUN.t, MAG.t).max() > np.searchsorted(RUN.t, MAG.t)[1]  # samples between steps
    yaw = RUN.truth[:, 6]
    assert (np.abs(np.diff(yaw)) > np.pi).any()  # the heading wraps
    per_step = np.bincount(np.searchsorted(RUN.t, MAG.t))
    assert per_step.max() >= 2  # more than one heading in a step


@pytest.mark.parametrize("factory", [quad3d_ekf, quad3d_ukf], ids=["EKF", "UKF"])
def test_a_gated_filter_runs_on_the_engine(factory, assert_same_run):
    """With a gate the filters still run compiled (the engine gates each GPS group and resets it
    after 1 s), and reject and reset what the readable loop does."""
    gps_z = RUN.gps.z.copy()
    gps_z[40:45, :3] += 30.0  # a jump
    gps_z[100:, 1] += 15.0  # and a jump that stays: the position group is reset
    gps = Samples(RUN.gps.t, gps_z)
    gated = estimate_quad3d(RUN.t, U, gps, MAG, RUN.truth[0], GATED, filter_factory=factory)
    assert gated.engine == "compiled"
    trace = gated.sensors["gps"]
    assert trace.rejected.any() and trace.reset.any() and (trace.rejected & trace.used).any()
    assert_same_run(gated, estimate_quad3d(RUN.t, U, gps, MAG, RUN.truth[0], GATED,
                                            filter_factory=factory, compiled=False))


@pytest.mark.parametrize("kind", ["EKF", "UKF"])
def test_a_changed_model_gives_the_changed_models_answer(kind, assert_same_run):
    """A model changed with dataclasses.replace: to a kernel with other parameters it runs on the
    engine, to a plain-Python Q on the readable loop (which says so); both give the changed model's answer."""
    params = Quad3DParams()
    model = params.model()
    louder = replace(model, Q=Kernel("Q", quad3d_maths.quad3d_noise, 10.0 * model.Q.params))
    in_python = replace(model, Q=lambda dt: 100.0 * model.Q(dt))

    def make(m):
        if kind == "EKF":
            return ModelEKF(m, X0, params.P0, 0.02)
        return ModelUKF(m, X0, params.P0, 0.02, **quad3d_ukf_options())

    gps, mag = params.sensors()
    measurements = [Measurements(gps, GPS.t, GPS.z), Measurements(mag, MAG.t, MAG.z)]
    runs = {}
    for name, m in (("original", model), ("louder", louder), ("in python", in_python)):
        runs[name] = run_filter(make(m), RUN.t, U, measurements, 0.999)
        assert_same_run(runs[name], run_filter(make(m), RUN.t, U, measurements, 0.999, engine="readable"))
    assert runs["louder"].engine == "compiled"
    assert runs["in python"].engine == "readable" and "Q is plain Python" in runs["in python"].engine_note
    assert_same_run(runs["louder"], runs["in python"])  # (10 σ)² is 100 Q: the same changed model
    assert np.abs(runs["louder"].x - runs["original"].x).max() > 1e-3


def test_a_non_finite_estimate_is_named_where_it_happens():
    """The engine hands a run that became non-finite to the readable loop, which names the step."""
    u = RUN.u.copy()
    u[100, 0] = 1e308  # the velocity overflows in the step to 101
    with np.errstate(over="ignore", invalid="ignore"), \
            pytest.raises(FilterDivergedError, match="non-finite at t\\[101\\]") as err:
        estimate_quad3d(RUN.t, u, RUN.gps, RUN.mag, RUN.truth[0])
    assert err.value.run.engine == "readable" and "non-finite" in err.value.run.engine_note
