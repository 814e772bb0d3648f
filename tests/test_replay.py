import re
from dataclasses import replace

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, run_filter
from quadlib.quad.height import height_model, range_sensor
from quadlib.sim.simulate import sample_sensor, simulate_model, with_dropouts


@pytest.fixture
def scenario():
    model, sensor = height_model(0.2), range_sensor(0.3, rate_hz=10)
    rng = np.random.default_rng(42)
    t = np.arange(0, 20, 0.02)
    u = np.full((t.size, 1), 0.3)
    x = simulate_model(model, [1.0], t, u, rng)
    return model, sensor, t, u, x, sample_sensor(sensor, t, x, rng), rng


def test_run_filter_shapes_and_accuracy(scenario):
    model, sensor, t, u, x, meas, _ = scenario
    run = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [meas])
    assert run.x.shape == (t.size, 1) and run.P.shape == (t.size, 1, 1)
    tr = run.sensors["range"]
    assert meas.t.size == 200 and tr.used.all() and not tr.missing.any()
    err = run.x[:, 0] - x[:, 0]
    assert np.sqrt(np.mean(err**2)) < 0.3 / 2  # much better than one raw sample
    assert np.mean(np.abs(err) <= 2 * run.sigma[:, 0]) > 0.9


def test_dropouts_are_skipped_and_counted(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    holed = with_dropouts(meas, rng, 0.3)
    z = holed.z.copy()
    z[(holed.t > 8) & (holed.t < 12)] = np.nan  # a 4 s outage
    holed = Measurements(sensor, holed.t, z)
    run = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [holed])
    tr = run.sensors["range"]
    assert tr.missing.sum() == np.isnan(z[:, 0]).sum() > 40
    assert tr.used.sum() == meas.t.size - tr.missing.sum()
    assert np.all(np.isnan(tr.nis[tr.missing]))
    # during the outage the filter keeps predicting and its uncertainty grows
    outage = (t > 8.1) & (t < 12)
    assert np.all(np.diff(run.sigma[outage, 0]) > 0)
    assert np.abs(run.x[:, 0] - x[:, 0]).max() < 1.0


def test_gate_counts_outliers(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    z = meas.z.copy()
    spikes = rng.choice(np.arange(20, z.shape[0]), 10, replace=False)
    z[spikes] += 3.0  # 10 sigma
    bad = Measurements(sensor, meas.t, z)
    gated = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [bad], gate_probability=0.999)
    plain = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [bad])
    tr = gated.sensors["range"]
    assert set(np.flatnonzero(tr.rejected)) >= set(spikes)
    assert tr.rejected.sum() <= 12  # few false alarms at 0.1 %
    err_gated = np.sqrt(np.mean((gated.x[:, 0] - x[:, 0]) ** 2))
    err_plain = np.sqrt(np.mean((plain.x[:, 0] - x[:, 0]) ** 2))
    assert err_gated < 0.8 * err_plain


def test_an_ungated_sensor_is_never_rejected(scenario):
    """Sensor.gated=False: the gate leaves that sensor alone, outliers and all (run_filter gates the others)."""
    model, sensor, t, u, x, meas, rng = scenario
    z = meas.z.copy()
    z[50] += 3.0  # 10 sigma: the gate refuses it when it may
    results = {}
    for gated in (True, False):
        m = Measurements(replace(sensor, gated=gated), meas.t, z)
        results[gated] = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [m], gate_probability=0.999)
    assert results[True].sensors["range"].rejected[50]
    trace = results[False].sensors["range"]
    assert not trace.rejected.any() and trace.used.all() and trace.nis[50] > 50
    with pytest.raises(TypeError, match="gated: expected True or False, got 1"):
        replace(sensor, gated=1)


def test_samples_apply_at_first_step_at_or_after_their_time():
    model, sensor = height_model(0.1), range_sensor(0.1)
    t = np.array([0.0, 0.1, 0.2, 0.3])
    meas = Measurements(sensor, [0.0, 0.15, 0.3], [[1.0], [2.0], [3.0]])
    f = ModelEKF(model, [0.0], [[100.0]], 0.1)
    run = run_filter(f, t, np.zeros((4, 1)), [meas])
    assert run.x[0, 0] == pytest.approx(1.0, abs=0.01)  # applied at t[0] before any predict
    assert run.x[1, 0] == pytest.approx(run.x[0, 0], abs=1e-12)  # nothing new at 0.1
    assert run.x[2, 0] > 1.5  # the 0.15 s sample lands at 0.2 s


def test_run_filter_input_errors(scenario):
    model, sensor, t, u, x, meas, _ = scenario
    f = ModelEKF(model, [1.0], [[0.1]], 0.02)
    with pytest.raises(ValueError, match="t: expected strictly increasing times"):
        run_filter(f, t[::-1], u, [meas])
    with pytest.raises(ValueError, match=r"u: expected shape \(1000, 1\), got \(999, 1\)"):
        run_filter(f, t, u[1:], [meas])
    with pytest.raises(ValueError, match=r"u: expected shape \(1000, 1\), got None"):
        run_filter(f, t, None, [meas])
    late = Measurements(sensor, meas.t + 100, meas.z)
    with pytest.raises(ValueError, match=r"measurements\[0\] \('range'\).t: expected times within"):
        run_filter(f, t, u, [late])
    with pytest.raises(ValueError, match="expected one entry per sensor name"):
        run_filter(f, t, u, [meas, meas])
    with pytest.raises(TypeError, match=r"measurements\[0\]: expected Measurements"):
        run_filter(f, t, u, [(meas.t, meas.z)])


def test_measurements_validation():
    s = range_sensor(0.1)
    with pytest.raises(ValueError, match=r"Measurements\('range'\).z: expected shape \(2, 1\), got \(3, 1\)"):
        Measurements(s, [0.0, 1.0], [[1.0], [2.0], [3.0]])
    with pytest.raises(ValueError, match="expected non-decreasing times"):
        Measurements(s, [1.0, 0.0], [1.0, 2.0])
    with pytest.raises(ValueError, match=r"got \d+ inf"):
        Measurements(s, [0.0, 1.0], [1.0, np.inf])


def test_run_filter_names_the_time_where_the_estimate_became_non_finite(scenario):
    model, sensor, t, u, x, meas, _ = scenario
    u = u.copy()
    u[500:, 0] = 1e308  # the height overflows to inf after some steps
    with np.errstate(over="ignore", invalid="ignore"), pytest.raises(FloatingPointError) as err:
        run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [meas])
    k = int(re.search(r"non-finite at t\[(\d+)\]", str(err.value)).group(1))
    assert k > 500 and f"= {t[k]:.6g} s" in str(err.value)
    partial = err.value.run  # nothing computed before the failure is lost
    assert err.value.index == k and partial.x.shape[0] == k and np.isfinite(partial.x).all()
    with np.errstate(over="ignore", invalid="ignore"):  # the same steps on their own: huge but finite
        clean = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t[:k], u[:k],
                           [Measurements(sensor, meas.t[meas.t < t[k]], meas.z[meas.t < t[k]])])
    np.testing.assert_array_equal(partial.x, clean.x)
    assert partial.sensors[sensor.name].t.max() < t[k]
    # the checked step-by-step API stops at the same step
    f = ModelEKF(model, [1.0], [[0.1]], 0.02)
    with np.errstate(over="ignore", invalid="ignore"), pytest.raises(FloatingPointError):
        for i in range(1, k + 1):
            f.predict(u[i - 1], dt=t[i] - t[i - 1])
            if np.any(np.isclose(meas.t, t[i])):
                f.update_sensor(sensor, meas.z[np.isclose(meas.t, t[i])][0])
    assert i == k


def test_run_filter_refuses_a_bare_filterpy_filter(scenario):
    from filterpy.kalman import KalmanFilter

    model, sensor, t, u, x, meas, _ = scenario
    with pytest.raises(TypeError, match="filt: expected a LinearKF, ModelEKF or ModelUKF, got KalmanFilter"):
        run_filter(KalmanFilter(dim_x=1, dim_z=1), t, u, [meas])


def test_run_filter_matches_a_loop_of_checked_calls(scenario):
    model, sensor, t, u, x, meas, _ = scenario
    run = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [meas], gate_probability=0.99)
    f = ModelEKF(model, [1.0], [[0.1]], 0.02)
    j = 0
    for k in range(t.size):
        if k:
            f.predict(u[k - 1], dt=t[k] - t[k - 1])
        while j < meas.t.size and meas.t[j] <= t[k] + 1e-9:
            f.update_sensor(sensor, meas.z[j], gate_probability=0.99)
            j += 1
        np.testing.assert_allclose(run.x[k], f.estimate, rtol=0, atol=1e-12)


def test_context_travels_with_each_sample_and_a_nan_context_is_a_missing_sample():
    from quadlib import Sensor

    model = height_model(0.5)
    gained = Sensor("gained", ("r",), context_names=("gain",), h=lambda x, c: c[0] * x[:1],
                    H=lambda x, c: np.array([[c[0]]]), R=[[0.04]])
    t = np.arange(6) * 0.1
    gain = np.array([1.0, 2.0, np.nan, 0.5, 1.0, 3.0])
    z = gain * np.array([1.0, 1.1, 1.2, 1.3, 1.4, 1.5])
    run = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.1), t, np.full(6, 0.5),
                     [Measurements(gained, t, z, context=gain)])
    trace = run.sensors["gained"]
    assert trace.missing.tolist() == [False, False, True, False, False, False]
    f = ModelEKF(model, [1.0], [[1.0]], 0.1)
    for k in range(6):  # the same by hand
        if k:
            f.predict([0.5], 0.1)
        if not np.isnan(gain[k]):
            f.update_sensor(gained, [z[k]], context=[gain[k]])
        np.testing.assert_allclose(run.x[k], f.estimate, rtol=1e-14)
    with pytest.raises(ValueError, match=r"Measurements\('gained'\).context: expected shape \(6, 1\)"):
        Measurements(gained, t, z)


def test_a_nan_input_row_holds_the_previous_input(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    u_gap = u.copy()
    u_gap[100:110] = np.nan
    run = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u_gap, [meas])
    reference = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u, [meas])  # u is constant: holding is exact
    np.testing.assert_array_equal(run.x, reference.x)
    assert run.held_input.sum() == 10 and run.held_input[100:110].all()
    u_first = u.copy()
    u_first[0] = np.nan
    with pytest.raises(ValueError, match="u: expected a finite first input to hold over later NaN rows"):
        run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u_first, [meas])


def test_a_repeated_timestamp_is_dropped_and_counted_not_fused_twice(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    doubled = Measurements(sensor, np.repeat(meas.t, 2), np.repeat(meas.z, 2, axis=0))
    once = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u, [meas])
    twice = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u, [doubled])
    np.testing.assert_array_equal(twice.P, once.P)  # σ does not shrink from fusing a copy
    trace = twice.sensors[sensor.name]
    assert trace.duplicate.sum() == meas.t.size and not trace.used[1::2].any()


def test_out_of_order_samples_are_named_by_index(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    times = meas.t.copy()
    times[5], times[6] = times[6], times[5]
    with pytest.raises(ValueError, match=r"t: expected non-decreasing times \(sort the log first\), got t\[6\]"):
        Measurements(sensor, times, meas.z)


def test_float32_timestamps_are_not_pushed_a_step_late(scenario):
    model, sensor, t, u, x, meas, rng = scenario
    exact = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u, [meas])
    rounded = run_filter(ModelEKF(model, [1.0], [[1.0]], 0.02), t, u,
                         [Measurements(sensor, meas.t.astype(np.float32), meas.z)])
    np.testing.assert_array_equal(rounded.x, exact.x)  # times only choose the step: every sample on the same one


def test_sensor_groups_must_partition_the_components():
    from quadlib import Sensor

    with pytest.raises(ValueError, match=r"Sensor\('g'\).groups: expected a partition of range\(3\)"):
        Sensor("g", ("a", "b", "c"), h=lambda x: x, R=np.eye(3), groups=((0, 1), (1, 2)))
    s = Sensor("g", ("a", "b", "c"), h=lambda x: x * 2, H=lambda x: 2 * np.eye(3), R=np.diag([1.0, 2.0, 3.0]),
               groups=((0, 2), (1,)))
    sub = s.subset([0, 2])
    np.testing.assert_array_equal(sub.h(np.array([1.0, 2.0, 3.0])), [2.0, 6.0])
    np.testing.assert_array_equal(sub.R, np.diag([1.0, 3.0]))


def test_a_frozen_sensor_is_skipped_when_the_sensor_says_it_cannot_repeat():
    from dataclasses import replace as _replace

    from quadlib import ModelEKF, run_filter
    from quadlib.quad.height import height_model, range_sensor

    t = np.arange(50) * 0.1
    z = 2.0 + np.random.default_rng(0).normal(0.0, 0.05, 50)
    z[20:35] = z[20]  # frozen for 1.5 s
    sensor = _replace(range_sensor(0.05), stuck_samples=3)
    run = run_filter(ModelEKF(height_model(0.1), [2.0], [[1.0]], 0.1), t, np.zeros((50, 1)),
                     [Measurements(sensor, t, z[:, None])])
    assert run.sensors["range"].missing.tolist() == [False] * 22 + [True] * 13 + [False] * 15
    with pytest.raises(ValueError, match=r"stuck_samples: expected an int >= 2 or None, got 1"):
        _replace(range_sensor(0.05), stuck_samples=1)


def test_rts_smooth_equals_filterpys_smoother_on_a_linear_model():
    from filterpy.kalman import KalmanFilter

    from quadlib import LinearKF, Model, Sensor, rts_smooth

    dt, q = 0.1, 0.5
    F = np.array([[1.0, dt], [0.0, 1.0]])
    Q = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    model = Model(state_names=("s [m]", "v [m/s]"), input_names=(), g=lambda x, u, dt: F @ x,
                  G=lambda x, u, dt: F, B=lambda x, u, dt: np.zeros((2, 0)), Q=lambda dt: Q)
    sensor = Sensor(name="position", measurement_names=("s [m]",), h=lambda x: x[:1],
                    H=lambda x: np.array([[1.0, 0.0]]), R=np.array([[0.4]]))
    rng = np.random.default_rng(1)
    t = dt * np.arange(200)
    z = (np.cumsum(rng.normal(0.0, 0.3, t.size)) + rng.normal(0.0, 0.6, t.size)).reshape(-1, 1)
    x0, P0 = np.array([0.0, 0.0]), np.diag([1.0, 4.0])
    run = run_filter(LinearKF(model, x0, P0, dt), t, None, [Measurements(sensor, t[1:], z[1:])])
    smoothed = rts_smooth(model, run, None)

    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.x, kf.P, kf.F, kf.Q, kf.H, kf.R = x0.reshape(-1, 1), P0.copy(), F, Q, sensor.H(x0), sensor.R
    means, covs, _, _ = kf.batch_filter(z[1:])
    ref_x, ref_P, _, _ = kf.rts_smoother(means, covs)
    np.testing.assert_allclose(run.x[1:], means[:, :, 0], atol=1e-10)
    np.testing.assert_allclose(smoothed.x[1:], ref_x[:, :, 0], atol=1e-9)
    np.testing.assert_allclose(smoothed.P[1:], ref_P, atol=1e-9)
    assert np.array_equal(smoothed.x[-1], run.x[-1])  # the last step has nothing after it
    assert (smoothed.P[1:-1, 0, 0] < run.P[1:-1, 0, 0]).all()


def test_rts_smooth_names_a_wrong_run():
    from quadlib import rts_smooth

    model = height_model(0.2)
    with pytest.raises(TypeError, match="run: expected a FilterRun"):
        rts_smooth(model, np.zeros((3, 1)), None)


def test_a_layout_names_columns_of_the_state(scenario):
    model, sensor, t, u, x, meas, _ = scenario
    run = run_filter(ModelEKF(model, [1.0], [[0.1]], 0.02), t, u, [meas])
    assert run.layout == {}
    named = replace(run, layout={"h": 0, "heights": slice(0, 1)})
    np.testing.assert_array_equal(named.h, run.x[:, 0])
    np.testing.assert_array_equal(named.heights, run.x)
    with pytest.raises(AttributeError, match=r"no attribute or state part 'q' \(parts: \['h', 'heights'\]\)"):
        named.q  # noqa: B018
    with pytest.raises(ValueError, match="layout: expected part names that are new attribute names, got 'sigma'"):
        replace(run, layout={"sigma": 0})
    with pytest.raises(TypeError, match=r"layout\['h'\]: expected a slice or a column index, got 'a'"):
        replace(run, layout={"h": "a"})
