"""Range-sensor dropouts and outliers on the 1D and 2D quadrotors: the filters keep running,
and with the NIS gate the outliers are rejected and counted."""

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, ModelUKF, run_filter
from quadlib.analysis.metrics import rmse
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
from quadlib.sim.simulate import sample_sensor, simulate_model, with_dropouts, with_outliers
from quadlib.sim.trajectories import piecewise_constant

DT = 0.02


def scenario_1d(rng):
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    t = np.arange(0.0, 20.0 + DT / 2, DT)
    u = piecewise_constant(t, [1, 3, 5, 10, 12, 14], [1.0, -1.0, 0.0, -0.5, 0.5, 0.0])[:, None]
    x = simulate_model(model, [0.0, 1.0], t, u, rng)
    return model, sensor, t, u, x, sample_sensor(sensor, t, x, rng), [0.0, 1.0], np.diag([0.25, 0.25])


def scenario_2d(rng):
    model, sensor = quad2d_model(0.2, np.radians(1.0)), quad2d_range_sensor(0.05, rate_hz=10)
    t = np.arange(0.0, 10.0 + DT / 2, DT)
    u = np.radians(piecewise_constant(t, [1, 2, 3, 6, 7, 8], [15.0, -15.0, 0.0, -15.0, 15.0, 0.0]))[:, None]
    x = simulate_model(model, [0.0, 0.0, 0.0], t, u, rng)
    return model, sensor, t, u, x, sample_sensor(sensor, t, x, rng), [0.0, 0.0, 0.0], np.diag([1e-4, 0.04, 0.09])


@pytest.mark.parametrize("make_scenario, position", [(scenario_1d, 1), (scenario_2d, 2)])
@pytest.mark.parametrize("cls", [ModelEKF, ModelUKF])
def test_dropouts_and_an_outage_leave_the_filter_running(make_scenario, position, cls):
    rng = np.random.default_rng(11)
    model, sensor, t, u, x, meas, x0, P0 = make_scenario(rng)
    holed = with_dropouts(meas, rng, 0.3)
    z = holed.z.copy()
    outage = (holed.t > 4.0) & (holed.t < 6.0)
    z[outage] = np.nan
    run = run_filter(cls(model, x0, P0, DT), t, u, [Measurements(sensor, holed.t, z)])
    tr = run.sensors["range"]
    assert tr.missing.sum() == np.isnan(z[:, 0]).sum() and tr.used.sum() == (~tr.missing).sum()
    assert np.isfinite(run.x).all()
    # σ grows during the outage and shrinks again after it
    s = run.sigma[:, position]
    i_before, i_end, i_after = np.searchsorted(t, [4.0, 5.98, 7.0])
    assert s[i_end] > 2 * s[i_before] and s[i_after] < 0.6 * s[i_end]
    assert np.mean(np.abs(run.x[:, position] - x[:, position]) <= 3 * s) > 0.95


@pytest.mark.parametrize("make_scenario, position", [(scenario_1d, 1), (scenario_2d, 2)])
@pytest.mark.parametrize("cls", [ModelEKF, ModelUKF])
def test_the_gate_rejects_and_counts_ten_sigma_outliers(make_scenario, position, cls):
    rng = np.random.default_rng(12)
    model, sensor, t, u, x, meas, x0, P0 = make_scenario(rng)
    bad, outlier = with_outliers(meas, rng, 0.15, noise_scale=10.0)
    plain = run_filter(cls(model, x0, P0, DT), t, u, [bad])
    gated = run_filter(cls(model, x0, P0, DT), t, u, [bad], gate_probability=0.999)
    rejected = gated.sensors["range"].rejected
    assert outlier.sum() >= 5 and np.isfinite(gated.x).all()
    # once the filter has converged (after 1 s), most big outliers are caught; few good samples are lost
    big = outlier & (np.abs(bad.z[:, 0] - meas.z[:, 0]) > 4 * np.sqrt(sensor.R[0, 0])) & (bad.t > 1.0)
    assert big.sum() >= 3
    assert rejected[big].mean() >= 0.8
    assert rejected[~outlier].mean() <= 0.02
    assert not plain.sensors["range"].rejected.any()
    err_plain = rmse(plain.x[:, position] - x[:, position])[()]
    err_gated = rmse(gated.x[:, position] - x[:, position])[()]
    assert err_gated < err_plain


def test_with_outliers_names_bad_arguments():
    rng = np.random.default_rng(0)
    _, sensor, t, _, x, meas, _, _ = scenario_1d(rng)
    with pytest.raises(ValueError, match="noise_scale: expected >= 1, got 0.5"):
        with_outliers(meas, rng, 0.1, noise_scale=0.5)
    with pytest.raises(ValueError, match="probability"):
        with_outliers(meas, rng, 1.5)
