"""FilterStepper: the closed loops step their filters with run_filter's own steps, so a replay of what
they logged gives the same estimates; and its bad arguments are named."""

import numpy as np
import pytest

from quadlib import Measurements, Model, ModelEKF, ModelUKF, Sensor, run_filter
from quadlib.control import altitude_step, fly, fly_path, hold_distance
from quadlib.quad import quad2d_model, quad2d_range_sensor
from quadlib.quad.flight import figure_eight
from quadlib.runs import FilterDivergedError
from quadlib.stepper import FilterStepper, Sample


def _replay(stepper, gate_probability, engine):
    """The stepper's log run again by run_filter, from a new filter at the stepper's start."""
    f = stepper.filt
    fresh = type(f)(f.model, *stepper.start, f.dt)
    t, u, measurements = stepper.log()
    return run_filter(fresh, t, u, measurements, gate_probability=gate_probability, engine=engine)


def _same(stepper, gate_probability, compiled: bool):
    """The replay on the readable loop (and on the compiled engine, where it runs) equals the loop's run."""
    stepped = stepper.run()
    engines = ("readable", "compiled") if compiled else ("readable",)
    for engine in engines:
        run = _replay(stepper, gate_probability, engine)
        assert run.engine == engine
        np.testing.assert_allclose(run.x, stepped.x, rtol=0, atol=1e-10)
        np.testing.assert_allclose(run.P, stepped.P, rtol=0, atol=1e-10)
        for name, tr in stepped.sensors.items():
            again = run.sensors[name]
            for flag in ("used", "rejected", "reset", "missing", "duplicate"):
                np.testing.assert_array_equal(getattr(again, flag), getattr(tr, flag), err_msg=f"{name}.{flag}")
    return stepped


def test_the_closed_loop_filters_replay_to_the_same_estimates():
    loop = fly(altitude_step(), 1.5, estimator="filters", rng=np.random.default_rng(3))
    attitude = _same(loop.steppers["attitude"], 0.9999, compiled=True)
    altitude = _same(loop.steppers["altitude"], None, compiled=False)  # a LinearKF: the readable loop only
    # the controller flew on exactly these estimates (the grid starts one period before the flight)
    np.testing.assert_array_equal(attitude.x[1:, :4], loop.q_est)
    np.testing.assert_array_equal(altitude.x[1:, 0], loop.height_est)
    assert attitude.sensors["heading"].t.size == loop.t.size // 5 + 1


def test_the_path_flown_on_the_ins_replays_to_the_same_estimates():
    path = figure_eight(duration_s=1.0, rate_hz=500.0)
    loop = fly_path(path, estimator="ins", rng=np.random.default_rng(4))
    from quadlib.nav.ins import InsParams

    _same(loop.steppers["ins"], InsParams().gate_probability, compiled=True)
    np.testing.assert_array_equal(loop.steppers["ins"].run().x[:, 7:10], loop.pos_est)


@pytest.mark.parametrize("kind", [ModelEKF, ModelUKF])
def test_the_planar_loop_replays_to_the_same_estimates(kind):
    wall, dt = 5.0, 0.05
    t = np.arange(0.0, 3.0 + dt / 2, dt)
    model, sensor = quad2d_model(0.2, np.radians(3.0)), quad2d_range_sensor(0.01, wall_y_m=wall)
    P0 = np.diag([np.radians(3.0) ** 2, 0.05**2, 0.1**2])
    loop = hold_distance(model, sensor, kind(model, [0.0, 0.0, wall - 2.0], P0, dt), t, [0.0, 0.0, wall - 1.9],
                         wall - 0.5, np.random.default_rng(0), sample_every=2)
    stepped = _same(loop.stepper, None, compiled=False)
    np.testing.assert_array_equal(stepped.x, loop.x)


def _cv():
    model = Model(state_names=("p", "v"), input_names=("a",), g=lambda x, u, dt: np.array([x[0] + dt * x[1],
                                                                                            x[1] + dt * u[0]]),
                  G=lambda x, u, dt: np.array([[1.0, dt], [0.0, 1.0]]), B=lambda x, u, dt: np.array([[0.0], [dt]]),
                  Q=lambda dt: np.eye(2) * dt, name="cv")
    pos = Sensor("pos", ("p",), h=lambda x: x[:1], H=lambda x: np.array([[1.0, 0.0]]), R=[[0.1]], stuck_samples=3)
    return model, pos


def test_held_inputs_duplicates_and_missing_or_stuck_samples_step_as_run_filter_replays_them():
    model, pos = _cv()
    t = np.arange(12) * 0.1
    u = np.sin(t)[:, None]
    u[[3, 4, 8]] = np.nan
    ts = np.r_[0.0, t[1:6], t[5], 0.65, t[7:]]  # a repeated time, a sample between steps
    z = np.cos(ts)[:, None]
    z[2] = np.nan
    z[8:11] = 0.5  # frozen: the third equal reading on is missing
    log = Measurements(pos, ts, z)
    stepper = FilterStepper(ModelEKF(model, [1.0, 0.0], np.eye(2), 0.1), [pos], gate_probability=0.99)
    for k, t_k in enumerate(t):
        mine = (ts > t[k - 1] + 1e-9) & (ts <= t_k + 1e-9) if k else ts <= t_k + 1e-9
        stepper.step(t_k, u[k - 1] if k else None, [Sample("pos", a, b) for a, b in zip(ts[mine], z[mine],
                                                                                         strict=True)])
    stepped = stepper.run()
    run = run_filter(ModelEKF(model, [1.0, 0.0], np.eye(2), 0.1), t, u, [log], gate_probability=0.99)
    np.testing.assert_array_equal(run.x, stepped.x)
    np.testing.assert_array_equal(stepped.held_input, np.isnan(u[:, 0]) & (np.arange(t.size) < t.size - 1))
    tr = stepped.sensors["pos"]
    assert tr.duplicate.tolist() == [j == 6 for j in range(ts.size)]
    assert np.flatnonzero(tr.missing).tolist() == [2, 10]
    np.testing.assert_array_equal(stepper.log()[1][:-1], u[:-1])


def _stepper():
    model, pos = _cv()
    return FilterStepper(ModelEKF(model, [0.0, 0.0], np.eye(2), 0.1), [pos])


@pytest.mark.parametrize(("kwargs", "name"), [
    (dict(filt="ekf"), "filt"),
    (dict(sensors="pos"), "sensors"),
    (dict(sensors=[1.0]), "sensors[0]"),
    (dict(sensors="twice"), "sensors"),
    (dict(gate_probability=1.5), "gate_probability"),
    (dict(time_resolution_s=-1.0), "time_resolution_s"),
    (dict(time_resolution_s=[1e-9, 1e-9]), "time_resolution_s"),
])
def test_bad_construction_is_named(kwargs, name):
    model, pos = _cv()
    args = dict(filt=ModelEKF(model, [0.0, 0.0], np.eye(2), 0.1), sensors=[pos])
    if kwargs.get("sensors") == "twice":
        kwargs = dict(sensors=[pos, pos])
    args.update(kwargs)
    with pytest.raises((TypeError, ValueError), match=rf"^{_escape(name)}: expected .* got"):
        FilterStepper(**args)


def _escape(name):
    return name.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")


@pytest.mark.parametrize(("first", "call", "name"), [
    (False, dict(t=np.nan), "t"),
    (True, dict(t=0.0, u=[0.0]), "t"),
    (False, dict(t=0.0, u=[0.0]), "u"),
    (True, dict(t=0.1), "u"),
    (True, dict(t=0.1, u=[0.0, 1.0]), "u"),
    (True, dict(t=0.1, u=[np.inf]), "u"),
    (True, dict(t=0.1, u=[np.nan]), "u"),
    (True, dict(t=0.1, u=[0.0], samples=Sample("pos", 0.1, [1.0])), "samples"),
    (True, dict(t=0.1, u=[0.0], samples=[(0.1, [1.0])]), "samples[0]"),
    (True, dict(t=0.1, u=[0.0], samples=[Sample("gps", 0.1, [1.0])]), "samples[0].sensor"),
    (True, dict(t=0.1, u=[0.0], samples=[Sample("pos", 0.1, [1.0, 2.0])]), "samples[0].z"),
    (True, dict(t=0.1, u=[0.0], samples=[Sample("pos", 0.1, [1.0], [2.0])]), "samples[0].context"),
    (True, dict(t=0.1, u=[0.0], samples=[Sample("pos", 0.2, [1.0])]), "samples[0].t"),
    (True, dict(t=0.1, u=[0.0], samples=[Sample("pos", 0.0, [1.0])]), "samples[0].t"),
    (False, dict(t=0.0, samples=[Sample("pos", 0.1, [1.0])]), "samples[0].t"),
])
def test_a_bad_step_is_named_and_leaves_the_filter_as_it_was(first, call, name):
    stepper = _stepper()
    if first:
        stepper.step(0.0)
    x, P = stepper.filt.estimate, stepper.filt.P.copy()
    with pytest.raises((TypeError, ValueError), match=rf"^{_escape(name)}: expected .* got"):
        stepper.step(**call)
    np.testing.assert_array_equal(stepper.filt.estimate, x)
    np.testing.assert_array_equal(stepper.filt.P, P)
    assert len(stepper.run().t) == int(first)


def test_a_step_that_diverges_raises_with_the_steps_before():
    model = Model(state_names=("p",), input_names=("a",), g=lambda x, u, dt: x + (np.inf if u[0] > 100 else u[0]),
                  G=lambda x, u, dt: np.eye(1), Q=lambda dt: np.eye(1) * dt, name="blows up above 100")
    stepper = FilterStepper(ModelEKF(model, [0.0], np.eye(1), 0.1), [])
    stepper.step(0.0)
    stepper.step(0.1, [1.0])
    with pytest.raises(FilterDivergedError, match="non-finite at t = 0.2") as err:
        stepper.step(0.2, [200.0])
    assert err.value.index == 2 and err.value.run.t.tolist() == [0.0, 0.1]
