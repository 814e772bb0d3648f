"""The batched filters — linear KF, EKF and UKF — equal the per-run loop, with dropouts, outliers and a gate."""

import numpy as np
import pytest

from quadlib import LinearKF, ModelEKF, ModelUKF
from quadlib.analysis.batched import _positive_definite, batch_supported, run_batch
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.filters import positive_definite
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
from quadlib.quad.quad2d import quad2d_model, quad2d_range_sensor
from quadlib.samples import Measurements


def _corrupt(samples, rng):
    out = []
    for m in samples:
        z = m.z.copy()
        z[rng.random(z.shape[0]) < 0.2] = np.nan  # dropouts
        spikes = rng.random(z.shape[0]) < 0.1
        z[spikes] += 10 * rng.standard_normal((spikes.sum(), z.shape[1]))  # outliers
        out.append(Measurements(m.sensor, m.t, z))
    return out


def _dropouts(samples, rng):
    out = []
    for m in samples:
        z = m.z.copy()
        z[rng.random(z.shape[0]) < 0.2] = np.nan
        out.append(Measurements(m.sensor, m.t, z))
    return out


def _assert_same_runs(batched, looped):
    for name in looped:
        a, b = batched[name], looped[name]
        np.testing.assert_array_equal(a.truth, b.truth)
        np.testing.assert_allclose(a.errors, b.errors, rtol=0, atol=1e-10)
        np.testing.assert_allclose(a.sigma, b.sigma, rtol=0, atol=1e-10)
        np.testing.assert_allclose(a.nees, b.nees, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(a.nis["range"], b.nis["range"], rtol=1e-9, atol=1e-9)
        np.testing.assert_array_equal(a.rejected["range"], b.rejected["range"])


@pytest.mark.parametrize("gate", [None, 0.999])
def test_batched_equals_one_run_at_a_time(gate):
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1, rate_hz=10)
    t = np.arange(0.0, 4.0 + 1e-9, 0.02)
    u = np.column_stack([np.sin(t)])
    filters = {"tuned": lambda x0, P0: LinearKF(model, x0, P0, 0.02),
               "Q/10": lambda x0, P0: LinearKF(quad1d_model(0.1), x0, P0, 0.02)}
    args = (filters, model, [sensor], [0.0, 1.0], np.diag([0.25, 0.25]), t, u, 25)
    kw = dict(corrupt=_corrupt, gate_probability=gate)
    batched = run_monte_carlo(*args, np.random.default_rng(3), batched=True, **kw)
    looped = run_monte_carlo(*args, np.random.default_rng(3), batched=False, **kw)
    _assert_same_runs(batched, looped)
    if gate is not None:
        assert batched["tuned"].rejected["range"].sum() > 0  # the gate was exercised


@pytest.mark.parametrize("gate", [None, 0.999])
def test_the_batched_ekf_and_ukf_equal_one_run_at_a_time(gate):
    """Chapter 9's wall-following quadrotor near the wall (where the range is most nonlinear), a
    range sensor at half the step rate with dropouts (and 10 m outliers for the gate to reject:
    ungated, they make the filters diverge, where rounding differences grow without bound), and a
    UKF with other sigma-point weights that assumes a far more precise sensor than the truth's."""
    model, dt = quad2d_model(0.2, np.radians(3.0)), 0.05
    t = np.arange(0.0, 3.0 + dt / 2, dt)
    u = -np.radians(15.0) * np.cos(2.5 * t)[:, None]
    P0 = np.diag([np.radians(3.0) ** 2, 0.05**2, 0.1**2])
    precise = quad2d_range_sensor(1e-6, wall_y_m=6.0, rate_hz=10)
    filters = {"EKF": lambda a, b: ModelEKF(model, a, b, dt), "UKF": lambda a, b: ModelUKF(model, a, b, dt),
               "UKF, α = 1": lambda a, b: ModelUKF(model, a, b, dt, alpha=1.0, kappa=1.0)}
    args = (filters, model, [quad2d_range_sensor(0.01, wall_y_m=6.0, rate_hz=10)], [0.0, 0.0, 4.0], P0, t, u, 20)
    kw = dict(corrupt=_corrupt if gate else _dropouts, gate_probability=gate, assumed_sensors={"UKF, α = 1": [precise]})
    batched = run_monte_carlo(*args, np.random.default_rng(5), batched=True, **kw)
    looped = run_monte_carlo(*args, np.random.default_rng(5), batched=False, **kw)
    _assert_same_runs(batched, looped)
    assert np.isfinite(batched["UKF"].errors).all()
    if gate is not None:
        assert all(batched[name].rejected["range"].sum() > 0 for name in filters)  # the gate was exercised


def test_the_batched_covariance_repair_is_the_per_run_one():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(4, 3, 3))
    P = A @ np.swapaxes(A, 1, 2) + 1e-3 * np.eye(3)
    P[2] = np.diag([1.0, 1e-3, -1e-9])  # rounding made one indefinite
    P[3, 0, 1] += 1e-12  # and one not quite symmetric
    repaired = _positive_definite(P.copy())
    np.testing.assert_array_equal(repaired, [positive_definite(p) for p in P])
    assert np.linalg.eigvalsh(repaired[2]).min() > 0.0


def test_run_batch_refuses_what_it_cannot_compute_exactly():
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1)
    ekf = ModelEKF(model, [0.0, 1.0], np.eye(2), 0.02)
    with pytest.raises(ValueError, match="filt: expected a filter and sensors run_batch supports"):
        run_batch(ekf, np.zeros((2, 2)), [0.0, 0.02], None, [[Measurements(sensor, [0.0], [[1.0]])]] * 2)


def test_only_what_the_batch_computes_exactly_is_batched():
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1)
    kf = LinearKF(model, [0.0, 1.0], np.eye(2), 0.02)
    assert batch_supported(kf, [sensor], None) and batch_supported(kf, [sensor], 0.99)
    assert not batch_supported(ModelEKF(model, [0.0, 1.0], np.eye(2), 0.02), [sensor], None)
    from dataclasses import replace

    assert not batch_supported(kf, [replace(sensor, reset_after_s=1.0)], 0.99)
    assert batch_supported(kf, [replace(sensor, reset_after_s=1.0)], None)
    planar, wall = quad2d_model(0.2, 0.05), quad2d_range_sensor(0.01)
    for kind in (ModelEKF, ModelUKF):
        filt = kind(planar, [0.0, 0.0, 3.0], np.eye(3), 0.05)
        assert batch_supported(filt, [wall], None) and batch_supported(filt, [wall], 0.99)
        assert not batch_supported(filt, [replace(wall, vectorized=False)], None)
        assert not batch_supported(filt, [replace(wall, mean=lambda Z, w: w @ Z)], None)
    assert not batch_supported(ModelEKF(replace(planar, vectorized=False), [0.0, 0.0, 3.0], np.eye(3), 0.05), [wall],
                               None)
    assert not batch_supported(ModelUKF(planar, [0.0, 0.0, 3.0], np.eye(3), 0.05, residual_x=np.subtract,
                                        x_mean_fn=lambda s, w: w @ s), [wall], None)
