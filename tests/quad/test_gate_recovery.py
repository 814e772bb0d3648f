"""Gates that recover: after a GPS outage of up to 60 s, or a 20 m jump that persists, the 3D
filters use GPS again within 2 s of it being plausible and are within 1 m 5 s later (gate on)."""

import numpy as np
import pytest

from quadlib import Measurements, ModelEKF, ModelUKF, run_filter
from quadlib.quad.estimate import Quad3DParams
from quadlib.quad.flight import SensorNoise3D, figure_eight, square_course
from quadlib.quad.quad3d import quad3d_gps_sensor, quad3d_ukf_options
from quadlib.quad.scenario import simulate_run3d

PARAMS = Quad3DParams()
GATE = 0.99


@pytest.fixture(scope="module")
def run():
    """A brisk 80 s figure eight: dead reckoning drifts ~15 m in 5 s and ~310 m in 60 s, enough
    for a plain 99 % gate to lock GPS out for good after every outage of 5 s or more."""
    return simulate_run3d(figure_eight(duration_s=80.0, period_s=10.0), SensorNoise3D(), np.random.default_rng(21))


@pytest.fixture(scope="module")
def gentle():
    """An 80 s square with 18 s legs: slow enough that dead reckoning stays within metres."""
    return simulate_run3d(square_course(leg_s=18.0, turn_s=2.0), SensorNoise3D(), np.random.default_rng(21))


def _run(run, gps_z, ukf=False, gps_sensor=None):
    gps_sensor = gps_sensor or PARAMS.sensors()[0]
    mag = PARAMS.sensors()[1]
    x0 = run.truth[0]
    f = (ModelUKF(PARAMS.model(), x0, PARAMS.P0, 0.02, **quad3d_ukf_options()) if ukf
         else ModelEKF(PARAMS.model(), x0, PARAMS.P0, 0.02))
    return run_filter(f, run.t, run.u, [Measurements(gps_sensor, run.gps.t, gps_z),
                                        Measurements(mag, run.mag.t, run.mag.z)], gate_probability=GATE)


def _first_use_after(res, t0):
    trace = res.sensors["gps"]
    used = trace.t[(trace.t >= t0 - 1e-9) & trace.used]
    return used[0] - t0


@pytest.mark.parametrize(("outage_s", "ukf"), [(5.0, False), (10.0, False), (20.0, False), (60.0, False),
                                               (60.0, True)])
def test_gps_is_used_again_after_an_outage(run, outage_s, ukf):
    start, end = 8.0, 8.0 + outage_s
    gps_z = run.gps.z.copy()
    gps_z[(run.gps.t >= start) & (run.gps.t < end)] = np.nan
    res = _run(run, gps_z, ukf)
    assert _first_use_after(res, end) <= 2.0
    k = np.searchsorted(run.t, end + 5.0)
    assert np.linalg.norm(res.x[k, :3] - run.truth[k, :3]) < 1.0


@pytest.mark.parametrize("ukf", [False, True])
def test_a_persistent_20_m_jump_is_followed_after_the_reset(run, ukf):
    jump = np.array([20.0, 0.0, 0.0])
    gps_z = run.gps.z.copy()
    after = run.gps.t >= 8.0
    gps_z[after, :3] += jump
    res = _run(run, gps_z, ukf)
    trace = res.sensors["gps"]
    assert trace.rejected[after][:3].all()  # first the gate holds it off, as a glitch
    assert trace.reset[after].sum() >= 1 and _first_use_after(res, 8.0) <= 2.0
    k = np.searchsorted(run.t, 8.0 + 2.0 + 5.0)
    assert np.linalg.norm(res.x[k, :3] - (run.truth[k, :3] + jump)) < 1.0


def test_without_a_reset_a_jump_locks_position_out_for_good_while_velocity_is_used(gentle):
    run = gentle
    jump = np.array([20.0, 0.0, 0.0])
    gps_z = run.gps.z.copy()
    gps_z[run.gps.t >= 8.0, :3] += jump
    res = _run(run, gps_z, gps_sensor=quad3d_gps_sensor(reset_after_s=None))
    trace = res.sensors["gps"]
    late = trace.t > 10.0
    assert trace.rejected[late].all() and not trace.reset.any()  # position never comes back
    assert trace.used[late].mean() > 0.95  # velocity is a group of its own (a 99 % gate drops ~1 % of good ones)
    k = np.searchsorted(run.t, 40.0)
    assert np.linalg.norm(res.x[k, :3] - (run.truth[k, :3] + jump)) > 15.0  # still on the old position
    assert np.linalg.norm(res.x[run.t > 10.0, 3:6] - run.truth[run.t > 10.0, 3:6], axis=1).max() < 1.0


@pytest.mark.parametrize("outage_s", [5.0, 60.0])
def test_without_a_reset_an_outage_locks_gps_out_for_good(run, outage_s):
    end = 8.0 + outage_s
    gps_z = run.gps.z.copy()
    gps_z[(run.gps.t >= 8.0) & (run.gps.t < end)] = np.nan
    res = _run(run, gps_z, gps_sensor=quad3d_gps_sensor(reset_after_s=None))
    trace = res.sensors["gps"]
    assert trace.rejected[trace.t > end + 2.0].all()
    k = np.searchsorted(run.t, end + 5.0)
    assert np.linalg.norm(res.x[k, :3] - run.truth[k, :3]) > 10.0
