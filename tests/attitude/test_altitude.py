import numpy as np
import pytest
import sympy as sp

from quadlib import LinearKF, Measurements, run_filter
from quadlib.attitude.altitude import (
    altitude_from_pressure,
    altitude_model,
    baro_altitude_sensor,
    pressure_from_altitude,
    vertical_specific_force,
)
from quadlib.constants import G0
from quadlib.geometry.quaternion import quat_from_euler, quat_to_dcm
from quadlib.sim.trajectories import vertical_sine


def test_transition_is_eq_2_68_and_integrates_constant_acceleration_exactly():
    m = altitude_model(0.06, 0.01)
    tau = 0.004
    s, v, gt, az, t = sp.symbols("s v gtilde a_z tau", real=True)
    acc = az - gt  # held over the step
    exact = sp.Matrix([s + v * t + acc * t**2 / 2, v + acc * t])
    x, u = np.array([10.0, -0.5, 9.7]), np.array([10.3])
    values = {s: x[0], v: x[1], gt: x[2], az: u[0], t: tau}
    np.testing.assert_allclose(m.g(x, u, tau)[:2], np.array(exact.subs(values), dtype=float).ravel(), atol=1e-14)
    assert m.g(x, u, tau)[2] == pytest.approx(0.99 * 9.7 + 0.01 * 10.3)
    np.testing.assert_allclose(m.g(x, u, tau), m.G(x, u, tau) @ x + m.B(x, u, tau)[:, 0] * u[0])  # linear
    b = m.B(x, u, tau)
    np.testing.assert_allclose(m.Q(tau), 0.06**2 * b @ b.T)  # eqs. (2.69)-(2.70)


def test_vertical_specific_force_is_g_at_rest_whatever_the_tilt():
    for roll, pitch in [(0.0, 0.0), (0.4, -0.3), (1.2, 0.5)]:
        q = quat_from_euler(roll, pitch, 0.7)
        f_b = -quat_to_dcm(q).T @ [0.0, 0.0, G0]
        assert vertical_specific_force(q, f_b) == pytest.approx(G0)


def test_gravity_state_absorbs_an_accelerometer_bias():
    rng = np.random.default_rng(4)
    dt, n = 0.004, 15_000  # 60 s at rest, 2 m above the start
    t = np.arange(n) * dt
    bias = 0.2
    a_z = G0 + bias + rng.normal(0, 0.06, n)
    k = np.arange(0, n, 10)
    baro = Measurements(baro_altitude_sensor(0.39), t[k], 2.0 + rng.normal(0, 0.39, k.size))
    run = run_filter(LinearKF(altitude_model(0.06, 2e-4), [0.0, 0.0, G0], np.diag([4.0, 0.1, 0.01]), dt),
                     t, a_z[:, None], [baro])
    assert run.x[-1, 2] == pytest.approx(G0 + bias, abs=0.02)
    assert abs(run.x[-1, 0] - 2.0) < 0.3 and abs(run.x[-1, 1]) < 0.1


def test_barometric_formula_and_its_rounded_inverse():
    assert pressure_from_altitude(0.0) == pytest.approx(1013.25)
    assert pressure_from_altitude(1000.0) == pytest.approx(898.7, abs=0.1)  # standard atmosphere
    s = np.array([0.0, 100.0, 1000.0])
    err = altitude_from_pressure(pressure_from_altitude(s)) - s
    assert abs(err[1]) < 0.2 and 1.0 < abs(err[2]) < 2.0  # the rounded 0.19 costs 0.15 % of the altitude
    with pytest.raises(ValueError, match="pressure_hpa: expected positive pressures"):
        altitude_from_pressure([1000.0, -1.0])


def test_a_clipped_accelerometer_sample_adds_uncertainty_and_the_barometer_takes_over():
    """A 50 ms, 30 g shock read as 16 g (the full scale) over a vertical sine: the integrated
    speed is 7 m/s off. Knowing the range, the filter widens its variance in those steps."""
    t, s, a_z, samples = vertical_sine(40.0, np.random.default_rng(9))
    shock = (t >= 10.0) & (t < 10.05)
    a_z[shock] = np.clip(a_z[shock] + 30 * G0, -16 * G0, 16 * G0)
    baro = Measurements(baro_altitude_sensor(0.39), samples.t, samples.z[:, None])
    errors = {}
    for full_scale in (None, 16 * G0):
        kf = LinearKF(altitude_model(0.06, 1e-5, full_scale), [0.0, 0.0, G0], np.diag([1.0, 0.1, 0.01]), t[1] - t[0])
        errors[full_scale] = np.abs(run_filter(kf, t, a_z[:, None], [baro], gate_probability=0.99).x[:, 0] - s)
    assert errors[16 * G0][t >= 10.0].max() < 2.0 and errors[16 * G0][t >= 12.0].max() < 0.5
    assert errors[None][t >= 10.0].max() > 5.0
    with pytest.raises(ValueError, match="accel_range_m_s2"):
        altitude_model(0.06, 1e-5, -1.0)
