"""Plausibility checks, and Kesten's filters riding through shocks, magnets and a stuck magnetometer."""

import numpy as np
import pytest

from quadlib.analysis.metrics import attitude_error
from quadlib.attitude.checks import SensorChecks, plausible_accel, plausible_mag, settled, undisturbed_field
from quadlib.attitude.kesten import FILTERS, AttitudeNoise, run_attitude_filter
from quadlib.attitude.tumble import random_rotation
from quadlib.imu import ImuLog
from quadlib.kernels.lowpass import undisturbed_field_pass
from quadlib.sim.imu import imu_samples

NOISE = AttitudeNoise()
MOTION = random_rotation(12.0, 250.0, np.random.default_rng(3))
LOG = imu_samples(MOTION, NOISE, np.random.default_rng(4), field_n=NOISE.field_n, mag_every=5)
T = LOG.t
FAULT = (T >= 5.0) & (T < 8.0)


def test_clean_samples_pass_and_each_fault_is_caught():
    checks = SensorChecks()
    assert plausible_accel(LOG.accel, checks).all()
    present = ~np.isnan(LOG.mag[:, 0])
    assert plausible_mag(LOG.mag, LOG.accel, NOISE.field_n, checks)[present].all()
    assert not plausible_accel([[0.0, 0.0, -0.3], [0.0, 29.4, -9.8]], checks).any()  # free fall, a 3 g shock
    f = np.array([[0.0, 0.0, -9.81]] * 7)
    field = NOISE.field_n
    turned = np.array([field[0] * np.cos(0.5), field[0] * np.sin(0.5), field[2]])  # heading changed: still fine
    dipped = np.array([field[0] * 0.2, 0.0, -np.sqrt(0.25 - (field[0] * 0.2) ** 2)])  # same strength, upward
    samples = np.array([field, turned, 10 * field, dipped, field, field, field])
    ok = plausible_mag(samples, f, field, SensorChecks(mag_stuck_samples=3))
    assert ok.tolist() == [True, True, False, False, True, True, False]  # magnet, wrong dip, third equal in a row
    assert plausible_mag(samples, f, field, SensorChecks(None, None, None, None))[:4].all()


@pytest.fixture(scope="module")
def clean_errors():
    return {name: np.degrees(attitude_error(run_attitude_filter(make(NOISE), LOG).q_nb, MOTION.q_nb))
            for name, make in FILTERS.items()}


def _faulty(kind):
    accel, mag = np.array(LOG.accel), np.array(LOG.mag)
    if kind == "stuck magnetometer":
        first = np.flatnonzero(FAULT & ~np.isnan(mag[:, 0]))[0]
        mag[FAULT & ~np.isnan(mag[:, 0])] = mag[first]
    elif kind == "magnet at 20x the field":
        mag[FAULT] += [10.0, 0.0, 0.0]  # fixed to the body, 20 times the Earth's 0.5 G
    elif kind == "3 g shock":
        accel[FAULT] += [0.0, 29.4, 0.0]
    elif kind == "free fall":
        accel[FAULT] = np.random.default_rng(5).normal(0.0, NOISE.accel_sigma_m_s2, (FAULT.sum(), 3))
    return ImuLog(T, LOG.gyro, accel, mag)


@pytest.mark.parametrize("kind", ["stuck magnetometer", "magnet at 20x the field", "3 g shock", "free fall"])
@pytest.mark.parametrize("name", list(FILTERS))
def test_every_filter_rides_through_the_fault_and_recovers(name, kind, clean_errors):
    clean = clean_errors[name]
    err = np.degrees(attitude_error(run_attitude_filter(FILTERS[name](NOISE), _faulty(kind)).q_nb, MOTION.q_nb))
    assert err[T > 3.0].max() < 2.0  # the gyro carries the attitude through three seconds of fault
    after = T > 10.0
    assert err[after].max() < clean[after].max() + 0.5  # back to the clean run's accuracy


def test_without_the_checks_the_filters_are_pulled_off():
    checks_off = SensorChecks(None, None, None, None)
    for kind in ("stuck magnetometer", "3 g shock"):
        err = np.degrees(attitude_error(run_attitude_filter(FILTERS["QKF"](NOISE, checks=checks_off),
                                                            _faulty(kind)).q_nb, MOTION.q_nb))
        assert err[FAULT].max() > 10.0


def test_bad_checks_are_named():
    with pytest.raises(TypeError, match="checks: expected a SensorChecks, got dict"):
        FILTERS["QF"](NOISE, checks={})


def test_the_dip_is_checked_against_an_attitude_when_one_is_given():
    """A sideways acceleration tilts the accelerometer's down by 27° and with it the dip it sees;
    measured against the attitude, the same field is plausible."""
    field = NOISE.field_n
    shaken = np.array([[5.0, 0.0, -9.81]])  # level sensor, 5 m/s² along x
    assert not plausible_mag(field[None], shaken, field, SensorChecks())[0]
    assert plausible_mag(field[None], None, field, SensorChecks(), q_nb=[[1.0, 0.0, 0.0, 0.0]])[0]
    tilted = [[np.cos(0.15), 0.0, np.sin(0.15), 0.0]]  # believed pitched by 17°: the dip looks wrong
    assert not plausible_mag(field[None], None, field, SensorChecks(), q_nb=tilted)[0]


def test_a_stream_is_trusted_again_only_once_it_has_settled():
    t = np.arange(12) * 0.1
    ok = np.array([1, 1, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1], bool)
    present = np.ones(12, bool)
    present[6] = ok[6] = False  # a missing sample neither fails nor restarts the clock
    expected = [1, 1, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1]  # from 0.5 s after the failure at 0.2 s
    assert settled(ok, present, t, 0.45).tolist() == [bool(e) for e in expected]
    with pytest.raises(ValueError, match="present: expected a bool array of shape"):
        settled(ok, present[:-1], t, 0.5)


def _level_field_readings(n, rng, dip_noise_deg):
    """A level sensor's field readings (body = NED), 100 Hz: 50 units at 60° dip, each reading's
    direction scattered by about ``dip_noise_deg``."""
    t = np.arange(n) * 0.01
    dip = np.radians(60.0 + dip_noise_deg * rng.standard_normal(n))
    mag = 50.0 * np.column_stack([np.cos(dip), np.zeros(n), np.sin(dip)])
    return t, mag, np.tile([0.0, 0.0, 1.0], (n, 1)), np.array([25.0, 0.0, 50.0 * np.sin(np.radians(60.0))])


def test_noisy_readings_are_judged_on_their_average_and_a_magnet_on_its_own():
    """Readings whose dip scatters by 6°: reading by reading, a 10° tolerance refuses about one in
    ten, and the settle time after each, most of them; averaged over 0.05 s, none. A magnet that
    doubles the norm for a second is refused from its second reading on (the first moves the
    average only a sixth of the way), and the field trusted again 0.5 s after it has gone."""
    t, mag, down, field = _level_field_readings(3000, np.random.default_rng(1), 6.0)
    field = field / np.linalg.norm(field) * 50.0
    magnet = (t >= 10.0) & (t < 11.0)
    mag[magnet] *= 2.0
    one_by_one = settled(plausible_mag(mag, -9.81 * down, field, SensorChecks()), np.ones(t.size, bool), t, 0.5)
    ok = undisturbed_field(t, mag, down, field, SensorChecks(), settle_s=0.5)
    quiet = ~magnet & ((t < 9.5) | (t > 12.0))
    assert one_by_one[quiet].mean() < 0.2 and ok[quiet].all()
    assert ok[magnet].sum() == 1 and ok[magnet][0] and not ok[(t >= 11.0) & (t < 11.45)].any() and ok[(t > 11.6)].all()
    args = (t, mag, down, np.full((t.size, 3), 1.0), 50.0, np.radians(60.0), 0.2, np.radians(10.0), 0.5, 0.05, 20.0,
            20.0, np.radians(20.0), 0.0)
    np.testing.assert_array_equal(undisturbed_field_pass.py_func(*args), undisturbed_field_pass(*args))


def test_the_reference_follows_a_field_that_changes_slowly():
    """The field's norm grows by 30 % over 100 s (another part of a room): the learnt reference
    follows it; the first reading's, within 20 %, refuses the last third."""
    t, mag, down, field = _level_field_readings(10_000, np.random.default_rng(2), 0.5)
    field = field / np.linalg.norm(field) * 50.0
    mag *= (1.0 + 0.3 * t / t[-1])[:, None]
    learnt = undisturbed_field(t, mag, down, field, SensorChecks(), settle_s=0.5)
    fixed = undisturbed_field(t, mag, down, field, SensorChecks(), settle_s=0.5, learn_tau_s=None)
    assert learnt.all()
    assert fixed[t < 60.0].all() and not fixed[t > 70.0].any()
    with pytest.raises(ValueError, match="down: expected an \\(N, 3\\) array"):
        undisturbed_field(t, mag, down[:, :2], field, SensorChecks())


def _turning_field_readings(seconds, rate_deg_s, board_field=(0.0, 0.0, 0.0)):
    """A level sensor yawing at ``rate_deg_s`` in a 50-unit field at 60° dip, 100 Hz, with a
    magnet's ``board_field`` fixed to the board: times, readings, down, gyro."""
    t = np.arange(int(seconds * 100)) * 0.01
    yaw = np.radians(rate_deg_s) * t
    earth = 50.0 * np.array([np.cos(np.radians(60.0)), 0.0, np.sin(np.radians(60.0))])
    mag = np.column_stack([earth[0] * np.cos(yaw), -earth[0] * np.sin(yaw), np.full(t.size, earth[2])])
    gyro = np.tile([0.0, 0.0, np.radians(rate_deg_s)], (t.size, 1))
    return t, mag + np.asarray(board_field), np.tile([0.0, 0.0, 1.0], (t.size, 1)), gyro


def test_a_wrong_reference_gives_way_to_a_field_that_holds_while_the_sensor_turns():
    """The reference says 30 % stronger than the field is: every reading is refused, until the
    field has held its norm and dip for 20 s of turning at 60 °/s; from then on, all are trusted.
    A magnet fixed to the board turns with it, its field's dip swinging by 40°, so it is never
    taken for the Earth's (the readings it leaves near the reference's norm and dip pass, as
    without the replacement); nor is any field while the sensor turns slower than 20 °/s."""
    wrong = 65.0 * np.array([np.cos(np.radians(60.0)), 0.0, np.sin(np.radians(60.0))])
    t, mag, down, gyro = _turning_field_readings(40.0, 60.0)
    ok = undisturbed_field(t, mag, down, wrong, SensorChecks(), gyro=gyro, new_field_s=20.0)
    assert not ok[t < 19.9].any() and ok[t > 20.1].all()
    assert not undisturbed_field(t, mag, down, wrong, SensorChecks()).any()  # without the gyro: never replaced
    assert not undisturbed_field(t, mag, down, wrong, SensorChecks(), gyro=0.0 * gyro, new_field_s=20.0).any()
    assert not undisturbed_field(t, mag, down, wrong, SensorChecks(), gyro=gyro * 0.3, new_field_s=20.0).any()
    t, magnet, down, gyro = _turning_field_readings(60.0, 60.0, board_field=(20.0, 0.0, 0.0))
    right = wrong / 65.0 * 50.0
    replaced = undisturbed_field(t, magnet, down, right, SensorChecks(), gyro=gyro, new_field_s=20.0)
    np.testing.assert_array_equal(replaced, undisturbed_field(t, magnet, down, right, SensorChecks()))


def test_a_first_field_on_trial_gives_way_to_one_that_holds_at_rest():
    """Switched on beside a magnet, at rest: the first 3 s of readings 1.5 times too strong. With the
    first reading as the reference, the true field after them is refused for good (at rest no new
    field is taken). With the reference on trial for its first 5 s of trust, the true field, steady
    from 3 s, replaces it at 8 s. A steady field is trusted throughout; a given reference is never on trial."""
    t, mag, down, field = _level_field_readings(2000, np.random.default_rng(6), 1.0)
    field = field / np.linalg.norm(field) * 50.0
    magnet = mag.copy()
    magnet[t < 3.0] *= 1.5
    first = undisturbed_field(t, magnet, down, None, SensorChecks(), settle_s=0.5)
    assert first[t < 2.9].all() and not first[t > 3.1].any()
    waited = undisturbed_field(t, magnet, down, None, SensorChecks(), settle_s=0.5, first_field_s=5.0)
    assert waited[t < 2.9].all() and not waited[(t > 3.1) & (t < 7.9)].any() and waited[t > 8.1].all()
    steady = undisturbed_field(t, mag, down, None, SensorChecks(), settle_s=0.5, first_field_s=5.0)
    assert steady.all()
    wrong = field * 1.5
    np.testing.assert_array_equal(undisturbed_field(t, mag, down, wrong, SensorChecks(), settle_s=0.5,
                                                    first_field_s=5.0),
                                  undisturbed_field(t, mag, down, wrong, SensorChecks(), settle_s=0.5))
    args = (t, magnet, down, np.zeros((t.size, 3)), np.nan, np.nan, 0.2, np.radians(10.0), 0.5, 0.05, 20.0,
            np.inf, np.radians(20.0), 5.0)
    np.testing.assert_array_equal(undisturbed_field_pass.py_func(*args), waited)


def test_without_a_reference_the_first_reading_is_the_reference():
    t, mag, down, field = _level_field_readings(2000, np.random.default_rng(5), 1.0)
    mag[1000:] *= 1.5  # a magnet arrives and stays
    given = undisturbed_field(t, mag, down, mag[0], SensorChecks(), settle_s=0.5)
    np.testing.assert_array_equal(undisturbed_field(t, mag, down, None, SensorChecks(), settle_s=0.5), given)
    assert given[:1000].all() and not given[1010:].any()
