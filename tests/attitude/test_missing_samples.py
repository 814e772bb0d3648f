"""A missing sample (a NaN row) in any stream barely changes the orientation estimate ten seconds later."""

from dataclasses import replace

import numpy as np
import pytest

from quadlib.analysis import attitude_error
from quadlib.attitude import orientation_run
from quadlib.data import data_path, load_broad_trial, load_ulog

LOGS = {"broad 02": load_broad_trial("02_undisturbed_slow_rotation_B").log.slice(0, 40_000),
        "sample.ulg": load_ulog(data_path("px4/sample.ulg")).imu}
BASE = {name: orientation_run(log).x[:, :4] for name, log in LOGS.items()}


@pytest.mark.parametrize("name", LOGS)
@pytest.mark.parametrize("stream", ["gyro", "accel", "mag"])
@pytest.mark.parametrize("where", [0.1, 0.5])
def test_one_missing_row_changes_the_estimate_by_under_005_deg_ten_seconds_later(name, stream, where):
    log = LOGS[name]
    values = getattr(log, stream).copy()
    present = np.flatnonzero(~np.isnan(values).any(axis=1))
    row = present[int(where * len(present))]
    values[row] = np.nan
    q = orientation_run(replace(log, **{stream: values})).x[:, :4]
    later = log.t >= log.t[row] + 10.0
    assert later.any()
    assert np.isfinite(q).all()
    assert np.degrees(attitude_error(q[later], BASE[name][later])).max() < 0.05
