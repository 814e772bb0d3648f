"""A reset that waits for the refused readings to agree (``Sensor.reset_needs_agreement``).

A gate that refuses a sensor for long may mean the estimate is off (the readings agree with one
another and all miss it) or the sensor is disturbed (they scatter more than its noise). The timed
reset follows the first only when asked; these tests check the χ² bound it uses, the whitening,
and the behaviour on one state measured directly.
"""

import numpy as np
import pytest
from scipy.stats import chi2

from quadlib import Measurements, Model, ModelEKF, Sensor, run_filter
from quadlib.kernels.linalg import add_refused, scatter_agrees
from quadlib.model_filter import agreement_test


@pytest.mark.parametrize("probability", [0.99, 0.999])
@pytest.mark.parametrize("dof", [3, 10, 100, 10_000])
def test_the_bound_is_the_chi2_quantile_within_two_percent(dof, probability):
    z = agreement_test(Sensor("a", ("a",), h=lambda x: x, R=[[1.0]]), probability)[1]
    quantile = chi2.ppf(probability, dof)
    for spread, expected in ((0.98 * quantile, True), (1.02 * quantile, False)):
        # dof + 1 readings, all 0 but the last, w: their scatter is w² − w²/(dof + 1) = spread
        w = np.sqrt(spread * (dof + 1) / dof)
        assert scatter_agrees(np.array([w, dof + 1.0, w * w]), 1.0, z) is expected


def test_the_scatter_is_about_the_readings_own_mean():
    rng = np.random.default_rng(1)
    w = rng.normal(size=(50, 2)) + [30.0, -40.0]  # far off zero, yet agreeing: unit noise about a mean
    acc = np.zeros((1, 4))  # one group of two rows: Σ w, the count, Σ |w|²
    for reading in w:
        add_refused(acc, reading, np.zeros(2, np.int64), np.ones(1, np.bool_))
    total, squares = w.sum(axis=0), float((w**2).sum())
    np.testing.assert_allclose(acc[0], np.r_[total, 50.0, squares], rtol=1e-12)
    scatter = float(((w - w.mean(axis=0)) ** 2).sum())
    z = agreement_test(Sensor("a", ("a", "b"), h=lambda x: x, R=np.eye(2)), 0.999)[1]
    assert scatter < chi2.ppf(0.999, 98) < squares  # about their mean they agree; about zero they would not
    assert scatter_agrees(acc[0], 2.0, z)
    assert not scatter_agrees(np.r_[3.0 * total, 50.0, 9.0 * squares], 2.0, z)  # the same readings × 3
    assert not scatter_agrees(np.r_[w[0], 1.0, w[0] @ w[0]], 2.0, z)  # one reading cannot agree


def test_the_whitening_makes_each_groups_noise_unit():
    R = np.array([[4.0, 1.0, 0.0], [1.0, 2.0, 0.0], [0.0, 0.0, 9.0]])
    sensor = Sensor("gps", ("x", "y", "v"), h=lambda x: x, R=R, groups=((0, 1), (2,)))
    W, z = agreement_test(sensor, 0.999)
    np.testing.assert_allclose(W @ R @ W.T, np.eye(3), atol=1e-12)
    assert W[0, 2] == W[2, 0] == 0.0  # block by block over the groups
    assert z == pytest.approx(3.0902, abs=1e-4)


def _level(readings: np.ndarray, agree: bool):
    """One constant level (σ 1 m at the start) read at 10 Hz by a sensor of σ 0.1 m, gated at 0.999, reset
    after 1 s. (The engine's own equality on such resets: tests/engine/test_ekf.py.)"""
    model = Model(("h",), (), g=lambda x, u, dt: x, G=lambda x, u, dt: np.eye(1), Q=lambda dt: 1e-8 * np.eye(1))
    sensor = Sensor("level", ("h [m]",), h=lambda x: x[:1], H=lambda x: np.eye(1), R=[[0.01]], reset_after_s=1.0,
                    reset_needs_agreement=agree)
    t = np.arange(readings.size) * 0.1
    filt = ModelEKF(model, [0.0], [[1.0]], 0.1)
    return run_filter(filt, t, None, [Measurements(sensor, t, readings[:, None])], gate_probability=0.999)


NOISE = np.random.default_rng(2).normal(0.0, 0.1, 200)


def test_readings_that_agree_reset_the_estimate_to_them():
    readings = NOISE + np.where(np.arange(200) >= 50, 2.0, 0.0)  # the level steps by 2 m (20 σ) at 5 s
    run = _level(readings, agree=True)
    trace = run.sensors["level"]
    assert trace.rejected[50:60].all() and trace.reset[60:62].any()  # refused for 1 s, then reset
    assert abs(run.x[-1, 0] - 2.0) < 0.05


def test_readings_that_scatter_stay_refused_where_a_plain_reset_takes_them():
    wild = np.where(np.arange(200) % 2, 3.0, 1.0)  # 1 or 3 m from 5 s on: a disturbance, not a new level
    readings = NOISE + np.where(np.arange(200) >= 50, wild, 0.0)
    agreeing, plain = _level(readings, agree=True), _level(readings, agree=False)
    assert not agreeing.sensors["level"].reset.any() and agreeing.sensors["level"].rejected[50:].all()
    assert abs(agreeing.x[-1, 0]) < 0.05
    assert plain.sensors["level"].reset.any() and plain.x[-1, 0] > 1.0  # the plain reset follows it



def test_a_reset_that_waits_for_agreement_needs_a_definite_r_and_a_reset():
    with pytest.raises(ValueError, match=r"Sensor\('a'\).R: expected a positive definite covariance with "
                                         r"reset_needs_agreement .*got smallest eigenvalue 0"):
        Sensor("a", ("a", "b"), h=lambda x: x, R=[[1.0, 1.0], [1.0, 1.0]], reset_after_s=1.0,
               reset_needs_agreement=True)
    with pytest.raises(ValueError, match=r"reset_needs_agreement: expected False without reset_after_s"):
        Sensor("a", ("a",), h=lambda x: x, R=[[1.0]], reset_needs_agreement=True)
