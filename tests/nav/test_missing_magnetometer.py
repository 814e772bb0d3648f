"""The INS on a log whose magnetometer is absent, all NaN or starts late."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.data import load_px4_log
from quadlib.nav import InsParams, estimate_ins

FLIGHT = load_px4_log()
BASE = estimate_ins(FLIGHT.imu, FLIGHT.gps, FLIGHT.baro, InsParams())


@pytest.mark.parametrize("mag", ["none", "all NaN"])
def test_without_magnetometer_readings_the_ins_runs_on_gps_alone(mag):
    field = None if mag == "none" else np.full_like(FLIGHT.imu.mag, np.nan)
    run = estimate_ins(replace(FLIGHT.imu, mag=field), FLIGHT.gps, FLIGHT.baro, InsParams())
    assert np.isfinite(run.x).all()
    assert "heading" not in run.sensors
    assert np.sqrt(np.mean(np.sum((run.x[:, 7:9] - BASE.x[:, 7:9]) ** 2, axis=1))) < 1.0


def test_a_late_first_magnetometer_reading_is_used():
    mag = FLIGHT.imu.mag.copy()
    mag[:500] = np.nan
    run = estimate_ins(replace(FLIGHT.imu, mag=mag), FLIGHT.gps, FLIGHT.baro, InsParams())
    assert run.sensors["heading"].used.sum() > 0.5 * BASE.sensors["heading"].used.sum()
    assert np.abs(run.x[-100:, 7:9] - BASE.x[-100:, 7:9]).max() < 0.5
