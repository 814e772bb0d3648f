"""The batched linear Kalman filter equals the per-run loop, with dropouts, outliers and a gate."""

import numpy as np
import pytest

from quadlib import LinearKF, ModelEKF
from quadlib.analysis.batched import batch_supported
from quadlib.analysis.montecarlo import run_monte_carlo
from quadlib.quad.quad1d import quad1d_model, quad1d_range_sensor
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
    for name in filters:
        a, b = batched[name], looped[name]
        np.testing.assert_array_equal(a.truth, b.truth)
        np.testing.assert_allclose(a.errors, b.errors, rtol=0, atol=1e-10)
        np.testing.assert_allclose(a.sigma, b.sigma, rtol=0, atol=1e-10)
        np.testing.assert_allclose(a.nees, b.nees, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(a.nis["range"], b.nis["range"], rtol=1e-9, atol=1e-9)
        np.testing.assert_array_equal(a.rejected["range"], b.rejected["range"])
    if gate is not None:
        assert batched["tuned"].rejected["range"].sum() > 0  # the gate was exercised


def test_only_what_the_batch_computes_exactly_is_batched():
    model, sensor = quad1d_model(0.3), quad1d_range_sensor(0.1)
    kf = LinearKF(model, [0.0, 1.0], np.eye(2), 0.02)
    assert batch_supported(kf, [sensor], None) and batch_supported(kf, [sensor], 0.99)
    assert not batch_supported(ModelEKF(model, [0.0, 1.0], np.eye(2), 0.02), [sensor], None)
    from dataclasses import replace

    assert not batch_supported(kf, [replace(sensor, reset_after_s=1.0)], 0.99)
    assert batch_supported(kf, [replace(sensor, reset_after_s=1.0)], None)
