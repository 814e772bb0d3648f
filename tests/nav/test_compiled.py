"""The INS on the compiled engine gives what the readable loop (ModelEKF driven by run_filter, and
rts_smooth, calling the same kernels) gives: the same states, covariances and sensor traces, to
1e-10 — on the real PX4 flight with faults added (a GPS jump that the gate rejects until its reset,
a GPS outage, a repeated fix, missing IMU rows and magnetometer samples), with both heading updates,
with and without the GPS height, offline, and without a barometer or magnetometer."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib import FilterDivergedError
from quadlib.data import load_px4_log
from quadlib.nav import InsParams, estimate_ins
from quadlib.samples import Samples

FLIGHT = load_px4_log()
PARAMS = InsParams(accel_sigma_m_s2=3.0, gps_pos_sigma_m=(1.0, 1.0, 2.5), gps_vel_sigma_m_s=(0.15, 0.15, 0.2),
                   baro_sigma_m=0.3, gps_delay_s=0.2)


def _faulty():
    """The first 40 s of the flight: GPS 25 m off to the east for 3 s from t = 20 s (rejected, then
    reset), no GPS for 4 s from 30 s, one fix repeated at the same time, 5 % of the IMU rows and
    10 % of the magnetometer samples missing."""
    rng = np.random.default_rng(3)
    imu = FLIGHT.imu.slice(0, int(np.searchsorted(FLIGHT.imu.t, FLIGHT.imu.t[0] + 40.0)))
    gyro, mag = imu.gyro.copy(), imu.mag.copy()
    gyro[200:][rng.random(len(imu) - 200) < 0.05] = np.nan
    mag[rng.random(len(imu)) < 0.1] = np.nan
    t0 = imu.t[0]
    gps_t, gps_z = FLIGHT.gps.t.copy(), FLIGHT.gps.z.copy()
    gps_z[(gps_t >= t0 + 20.0) & (gps_t < t0 + 23.0), 1] += 25.0
    gps_z[(gps_t >= t0 + 30.0) & (gps_t < t0 + 34.0)] = np.nan
    k = int(np.searchsorted(gps_t, t0 + 12.0))
    gps_t[k + 1] = gps_t[k]
    return replace(imu, gyro=gyro, mag=mag), Samples(gps_t, gps_z)


IMU, GPS = _faulty()


def _assert_equal(compiled, readable):
    np.testing.assert_allclose(compiled.x, readable.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(compiled.P, readable.P, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(compiled.t, readable.t)
    np.testing.assert_array_equal(compiled.held_input, readable.held_input)
    assert compiled.sensors.keys() == readable.sensors.keys()
    for name, c in compiled.sensors.items():
        r = readable.sensors[name]
        for field in ("innovation", "S", "nis"):
            np.testing.assert_allclose(getattr(c, field), getattr(r, field), rtol=0, atol=1e-10, err_msg=name)
        for field in ("t", "used", "rejected", "reset", "missing", "duplicate"):
            np.testing.assert_array_equal(getattr(c, field), getattr(r, field), err_msg=f"{name}.{field}")


def _both(imu=IMU, gps=GPS, baro=FLIGHT.baro, params=PARAMS, **kwargs):
    compiled = estimate_ins(imu, gps, baro, params, declination_rad=-0.1, **kwargs)
    assert compiled.engine == "compiled", compiled.engine_note
    readable = estimate_ins(imu, gps, baro, params, declination_rad=-0.1, compiled=False, **kwargs)
    assert readable.engine == "readable"
    _assert_equal(compiled, readable)
    return compiled


@pytest.mark.parametrize("tilt_aware", [False, True])
@pytest.mark.parametrize("use_gps_height", [False, True])
def test_the_compiled_ins_equals_the_readable_one_through_faults(tilt_aware, use_gps_height):
    run = _both(params=replace(PARAMS, heading_tilt_aware=tilt_aware, use_gps_height=use_gps_height))
    gps = run.sensors["gps"]
    assert gps.rejected.sum() >= 3 and gps.reset.sum() >= 1  # the jump: rejected, then reset
    assert (gps.used & gps.rejected).any()  # the velocity passed while the position was rejected
    assert gps.duplicate.sum() == 1 and gps.missing.sum() >= 15
    assert run.held_input.sum() > 50 and run.sensors["heading"].missing.sum() > 100
    assert run.sensors["heading"].used.sum() > 2000 and run.sensors["baro"].used.sum() > 2000


def test_the_compiled_smoother_equals_the_readable_one():
    run = _both(offline=True)
    assert run.sensors["gps"].reset.any()


def test_without_barometer_magnetometer_or_gate_and_with_blocks_of_two():
    run = _both(imu=replace(IMU, mag=None), baro=None, params=replace(PARAMS, gate_probability=None), decimate=2)
    assert run.sensors.keys() == {"gps"} and not run.sensors["gps"].rejected.any()


def test_a_diverging_log_is_named_by_the_readable_loop():
    accel = IMU.accel.copy()
    accel[1000] = 1e300  # the velocity overflows
    imu = replace(IMU, accel=accel)
    for compiled in (True, False):
        with np.errstate(over="ignore", invalid="ignore"), pytest.raises(FilterDivergedError) as err:
            estimate_ins(imu, GPS, FLIGHT.baro, PARAMS, compiled=compiled)
        assert err.value.run.t[-1] == IMU.t[1000]  # the step that row 1000 drives is the first non-finite one


@pytest.mark.parametrize("decimate", [0, 2.0, True])
def test_the_noise_of_a_block_needs_a_whole_number_of_samples(decimate):
    with pytest.raises(ValueError, match="decimate: expected an int >= 1"):
        PARAMS.noise(decimate)
    assert PARAMS.noise(4)[1].tolist() == [1.5, 1.5, 1.5]  # σ / √4


def test_compiled_must_be_a_bool():
    with pytest.raises(TypeError, match="compiled: expected True or False, got 1"):
        estimate_ins(IMU, GPS, FLIGHT.baro, PARAMS, compiled=1)
