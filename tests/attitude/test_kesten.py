"""Kesten's five attitude filters on run_filter: eq. 2.54, convergence, outages, and TQF/QF as
the scalar recursions of the thesis written out by hand."""

from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from quadlib.analysis.metrics import attitude_error
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, qf, run_attitude_filter, tqf
from quadlib.attitude.tumble import random_rotation, with_spin
from quadlib.geometry.quaternion import (
    integrate_body_rate,
    quat_conjugate,
    quat_from_rotvec,
    quat_multiply,
    quat_to_rotvec,
    vector_jacobian,
)
from quadlib.geometry.vector_attitude import attitude_from_accel_mag
from quadlib.imu import ImuLog
from quadlib.sim.imu import imu_samples

NOISE = AttitudeNoise()
MOTION = random_rotation(6.0, 250.0, np.random.default_rng(3))
T = MOTION.t


def _log(seed, **kw):
    return imu_samples(MOTION, NOISE, np.random.default_rng(seed), field_n=NOISE.field_n, **kw)


def _error_deg(est):
    return np.degrees(np.linalg.norm(quat_to_rotvec(quat_multiply(quat_conjugate(MOTION.q_nb), est)), axis=1))


def test_qkf_jacobian_is_eq_2_54():
    x1, x2, x3, x4, a3, m1, m3 = sp.symbols("x1 x2 x3 x4 a3 m1 m3", real=True)
    eq254 = 2 * sp.Matrix([
        [-a3 * x3, a3 * x4, -a3 * x1, a3 * x2], [a3 * x2, a3 * x1, a3 * x4, a3 * x3],
        [a3 * x1, -a3 * x2, -a3 * x3, a3 * x4],
        [m1 * x1 - m3 * x3, m1 * x2 + m3 * x4, -m1 * x3 - m3 * x1, m3 * x2 - m1 * x4],
        [m3 * x2 - m1 * x4, m1 * x3 + m3 * x1, m1 * x2 + m3 * x4, m3 * x3 - m1 * x1],
        [m1 * x3 + m3 * x1, m1 * x4 - m3 * x2, m1 * x1 - m3 * x3, m1 * x2 + m3 * x4]])
    q = np.array([0.8, -0.3, 0.4, 0.33])
    q /= np.linalg.norm(q)
    a_n, m_n = np.array([0.0, 0.0, -9.8]), np.array([0.2, 0.0, 0.45])
    ours = np.vstack([vector_jacobian(q, a_n), vector_jacobian(q, m_n)])
    printed = np.array(eq254.subs({x1: q[0], x2: q[1], x3: q[2], x4: q[3], a3: a_n[2], m1: m_n[0], m3: m_n[2]}),
                       dtype=float)
    np.testing.assert_allclose(ours, printed, atol=1e-12)


@pytest.mark.parametrize("name", list(FILTERS))
def test_every_filter_converges_and_keeps_a_unit_quaternion(name):
    result = run_attitude_filter(FILTERS[name](NOISE), _log(4, mag_every=5))
    assert _error_deg(result.q_nb)[T > 2.0].max() < 1.0  # from the identity to under a degree
    assert np.abs(np.linalg.norm(result.q_nb, axis=1) - 1.0).max() < 1e-9
    assert result.run.P.shape[1] == {"TOVKF": 3, "TQKF": 4, "TQF": 3, "QKF": 4, "QF": 6}[name]


@pytest.mark.parametrize("name", list(FILTERS))
def test_magnetometer_outage_and_free_fall_are_ridden_through(name):
    log = _log(5)
    accel, mag = np.array(log.accel), np.array(log.mag)
    outage = (T > 2.0) & (T < 3.0)
    fall = (T > 4.0) & (T < 4.5)
    mag[outage] = np.nan
    accel[fall] = np.random.default_rng(6).normal(0.0, NOISE.accel_sigma_m_s2, (fall.sum(), 3))  # free fall reads ~0
    est = run_attitude_filter(FILTERS[name](NOISE), ImuLog(log.t, log.gyro, accel, mag)).q_nb
    assert np.all(np.isfinite(est))
    assert _error_deg(est)[T > 1.5].max() < 1.5  # the gyro carries the attitude through both
    assert np.abs(np.linalg.norm(est, axis=1) - 1.0).max() < 1e-9


def _turn(z, z_hat):
    a, b = z / np.linalg.norm(z), z_hat / np.linalg.norm(z_hat)
    axis = np.cross(a, b)
    return axis / np.linalg.norm(axis) * np.arccos(np.clip(a @ b, -1, 1))


@pytest.mark.parametrize("thesis", [False, True])
def test_tqf_and_qf_equal_the_scalar_recursions_of_the_thesis(thesis):
    """TQF (eqs. 2.44–2.48) and QF (2.55–2.64) as Kesten writes them: a variance per correction,
    ``k = p / (p + r)``, ``q ← q ⊗ exp(k θ)``, ``p ← (1 − k) p``. The error-state EKFs must agree."""
    noise = AttitudeNoise(thesis_process_noise=thesis)
    log = _log(7, mag_every=3).slice(0, 400)
    dt = log.t[1] - log.t[0]
    q_step = noise.gyro_step_variance(dt)
    # TQF by hand
    q, p, out = np.array([1.0, 0, 0, 0]), 1.0, []
    r = 0.5 * (noise.r_accel + noise.r_mag)
    for k in range(len(log)):
        if k:
            q, p = integrate_body_rate(q, log.gyro[k - 1], dt), p + q_step
        if not np.isnan(log.mag[k, 0]):
            att = attitude_from_accel_mag(log.accel[k:k + 1], log.mag[k:k + 1])
            gain = p / (p + r)
            q, p = quat_multiply(q, quat_from_rotvec(gain * quat_to_rotvec(quat_multiply(quat_conjugate(q),
                                                                                         att.q_nb[0])))), (1 - gain) * p
        out.append(q.copy())
    np.testing.assert_allclose(run_attitude_filter(tqf(noise), log).q_nb, out, atol=1e-12)
    # QF by hand
    q, p, out = np.array([1.0, 0, 0, 0]), {"accel": 1.0, "mag": 1.0}, []
    refs = {"accel": (noise.accel_n, noise.r_accel), "mag": (noise.field_n, noise.r_mag)}
    for k in range(len(log)):
        if k:
            q = integrate_body_rate(q, log.gyro[k - 1], dt)
            p = {key: v + q_step for key, v in p.items()}
        for key, z in (("accel", log.accel[k]), ("mag", log.mag[k])):
            if np.isnan(z[0]):
                continue
            ref, r = refs[key]
            gain = p[key] / (p[key] + r)
            q = quat_multiply(q, quat_from_rotvec(gain * _turn(z, _predicted(q, ref))))
            p[key] *= 1 - gain
        out.append(q.copy())
    np.testing.assert_allclose(run_attitude_filter(qf(noise), log).q_nb, out, atol=1e-12)


def _predicted(q, ref):
    w, x, y, z = q
    C = np.array([[w * w + x * x - y * y - z * z, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), w * w - x * x + y * y - z * z, 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z]])
    return C.T @ ref


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="noise: expected an AttitudeNoise, got dict"):
        FILTERS["QF"]({})
    with pytest.raises(ValueError, match="sigma0_rad: expected a finite number > 0, got -1"):
        FILTERS["QKF"](NOISE, sigma0_rad=-1)
    with pytest.raises(TypeError, match="log: expected an ImuLog, got tuple"):
        run_attitude_filter(FILTERS["QF"](NOISE), (np.zeros((3, 3)),) * 3)
    with pytest.raises(ValueError, match=r"ImuLog.mag: expected shape \(3, 3\), got \(2, 3\)"):
        ImuLog(np.arange(3.0), np.zeros((3, 3)), np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"q0: expected shape \(\.\.\., 4\)"):
        run_attitude_filter(FILTERS["QF"](NOISE), _log(1).slice(0, 3), q0=[1, 0, 0])


@pytest.mark.parametrize("name", list(FILTERS))
def test_a_filter_that_knows_the_gyro_range_recovers_from_a_saturated_spin(name):
    """40 rad/s for 1 s through a gyro that clips at 2000 °/s: the integrated attitude ends far
    off; with the range known, the clipped steps add uncertainty and the vector sensors take over.
    QF is the slow one: after its first large turns its two variances are small again, and its
    two minimal turns (toward gravity, toward the field) pull against each other; the rest of its
    error decays with a time constant of about 20 s."""
    motion = with_spin(random_rotation(12.0, 250.0, np.random.default_rng(3)), 4.0, 1.0, 40.0)
    noise = replace(NOISE, gyro_range_rad_s=float(np.radians(2000.0)))
    log = imu_samples(motion, noise, np.random.default_rng(4), field_n=NOISE.field_n, mag_every=5)
    error = np.degrees(attitude_error(run_attitude_filter(FILTERS[name](noise), log).q_nb, motion.q_nb))
    blind = np.degrees(attitude_error(run_attitude_filter(FILTERS[name](NOISE), log).q_nb, motion.q_nb))
    after = motion.t >= 5.0 + 6.0
    assert error[after].max() < (20.0 if name == "QF" else 1.0)
    assert blind[motion.t.searchsorted(5.0 + 2.0)] > 10.0  # not knowing the range, two seconds on: far off


def test_the_tumble_is_integrate_body_rate_bit_for_bit():
    """random_rotation integrates with the one-quaternion kernels; every stored Fig. 5.2 number
    depends on its truth being eq. (2.7) exactly as integrate_body_rate computes it."""
    motion = random_rotation(2.0, 250.0, np.random.default_rng(10))
    q = motion.q_nb[:1].copy()
    for k in range(1, motion.t.size):
        q = np.vstack([q, integrate_body_rate(q[-1], motion.omega_b[k - 1], 1.0 / 250.0)])
    np.testing.assert_array_equal(q, motion.q_nb)
