"""The compiled fixed-wing filters — Salmony's EKF, the multiplicative EKF and the error-state UKF,
all on the engine — give what the readable ones (ModelEKF and ModelUKF driven by
run_filter) give: the same states, covariances and sensor traces, to 1e-10, through every branch —
dropouts in every stream, held gyro rows, a failed pitot, gate rejections, a saturated gyro, no
gate, a prefilter, a repeated timestamp."""

import numpy as np
import pytest

from quadlib.fixedwing.estimate import (
    FixedWingParams,
    error_state_ukf,
    estimate_fixedwing_attitude,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.fixedwing.model import FixedWingNoise
from quadlib.fixedwing.sim import aileron_roll, fixedwing_flight, fixedwing_samples
from quadlib.imu import ImuLog

NOISE = FixedWingNoise()


def _faulty_log():
    """The 25 Hz flight with 5 % of every stream missing, the pitot out for 10 s, the magnetometer
    turned by 30° for 3 s and a 4 m/s² push for 1 s (so the gate refuses samples)."""
    flight = fixedwing_flight(rate_hz=25.0)
    log = fixedwing_samples(flight, NOISE, np.random.default_rng(3))
    rng = np.random.default_rng(4)
    gyro, accel, mag, airspeed = (np.array(a) for a in (log.gyro, log.accel, log.mag, log.airspeed))
    for stream in (gyro, accel, mag, airspeed):
        stream[rng.random(len(log)) < 0.05] = np.nan
    gyro[:60] = log.gyro[:60]  # the initial state needs a still start, a held row a first one
    accel[:60], mag[:60] = log.accel[:60], log.mag[:60]
    airspeed[(log.t > 10.0) & (log.t < 20.0)] = np.nan
    turned = (log.t > 33.0) & (log.t < 36.0)
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    mag[turned] = mag[turned] @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    accel[(log.t > 50.0) & (log.t < 51.0)] += [4.0, 0.0, 0.0]
    return ImuLog(log.t, gyro, accel, mag, airspeed)


FAULTY = _faulty_log()
ROLL = aileron_roll(fixedwing_flight(rate_hz=50.0), 62.0, 42.0, turns=3)  # 42 rad/s: beyond the range
ROLL_NOISE = FixedWingNoise(gyro_range_rad_s=30.0)
ROLL_LOG = fixedwing_samples(ROLL, ROLL_NOISE, np.random.default_rng(5))

CASES = {
    "faults, gated": (FAULTY, NOISE, {}),
    "faults, no gate": (FAULTY, NOISE, {"params": FixedWingParams(gate_probability=None)}),
    "faults, 2 Hz prefilter, horizontal field": (FAULTY, NOISE, {"prefilter_hz": 2.0, "inclination_rad": 0.0}),
    "aileron rolls, saturated gyro": (ROLL_LOG, ROLL_NOISE, {}),
}


FILTERS = {"Salmony EKF": salmony_ekf, "multiplicative EKF": multiplicative_ekf, "ES-UKF": error_state_ukf}


@pytest.mark.parametrize("factory", list(FILTERS))
@pytest.mark.parametrize("case", list(CASES))
def test_the_compiled_loop_equals_the_readable_one(case, factory, assert_same_run):
    log, noise, kw = CASES[case]
    compiled = estimate_fixedwing_attitude(log, noise, FILTERS[factory], **kw)
    assert compiled.engine == "compiled"
    assert_same_run(compiled, estimate_fixedwing_attitude(log, noise, FILTERS[factory], compiled=False, **kw))


@pytest.mark.parametrize("factory", list(FILTERS))
def test_the_cases_reach_every_branch(factory):
    """The comparisons above are only worth something if each branch happened in them."""
    run = estimate_fixedwing_attitude(FAULTY, NOISE, FILTERS[factory])
    assert run.held_input.sum() > 50
    for name in ("accel", "accel (no airspeed)", "mag"):
        trace = run.sensors[name]
        assert trace.used.sum() > 100 and trace.missing.sum() > 50, name
    assert run.sensors["accel"].rejected.sum() > 5 and run.sensors["mag"].rejected.sum() > 5
    assert (np.abs(ROLL_LOG.gyro) >= 0.999 * 30.0).any(axis=1).sum() > 20  # saturated steps


@pytest.mark.parametrize("factory", list(FILTERS))
def test_a_repeated_timestamp_is_dropped_alike(factory, assert_same_run):
    """run_filter drops a sample whose time repeats the one before within its precision; the engine
    does the same."""
    short = FAULTY.slice(0, 300)
    t = short.t.copy()
    t[150] = t[149] + 1e-12  # the same time, within the clock's precision
    repeated = ImuLog(t, short.gyro, short.accel, short.mag, short.airspeed)
    run = estimate_fixedwing_attitude(repeated, NOISE, FILTERS[factory])
    assert run.sensors["mag"].duplicate[150]
    assert run.engine == "compiled"
    assert_same_run(run, estimate_fixedwing_attitude(repeated, NOISE, FILTERS[factory], compiled=False))


def test_a_covariance_the_sigma_points_cannot_factor_is_named_where_it_happens():
    """The engine's UKF stops where the covariance stops being positive definite and hands the log
    to the readable loop, which raises there."""
    log = FAULTY.slice(0, 200)
    gyro = log.gyro.copy()
    gyro[100] = 1e160  # the predict to step 101: φ·φ overflows
    broken = ImuLog(log.t, gyro, log.accel, log.mag, log.airspeed)
    with np.errstate(all="ignore"), pytest.raises(ValueError, match="P: expected a finite covariance for the sigma"):
        estimate_fixedwing_attitude(broken, NOISE, error_state_ukf)
