"""The fault matrix: every estimator against the sensor faults that apply to it, in one table.

Usage: ``python benchmarks/faults.py`` (about 8 minutes). Each cell is the peak error after the
fault starts (metres of horizontal position for the 3D quadrotor, metres of altitude for the
altitude filter, degrees of attitude for the attitude filters), the time after the fault ends until
the error stays below twice the clean run's peak (``never`` when it does not within the run), and
``!`` when the estimate became non-finite or a quaternion left the unit sphere. ``n/a``: the fault
does not apply to that estimator. Gates are on (99 % for the 3D quadrotor and the altitude filter,
99.9 % for the fixed-wing filters and the orientation MEKF; Kesten's filters run ungated, as in the
thesis, with the plausibility checks). Every IMU has a gyro that clips at 2000 °/s and an
accelerometer that clips at 16 g; the estimators know the gyro's range, the altitude filter the
accelerometer's. Rows that name no sensor are faults of
the position sensor: GPS for the 3D quadrotor, the barometer for the altitude filter.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from quadlib import LinearKF, ModelEKF, ModelUKF, Samples, run_filter
from quadlib.analysis.metrics import attitude_error
from quadlib.attitude import (
    FILTERS,
    AttitudeNoise,
    OrientationParams,
    altitude_model,
    baro_altitude_sensor,
    estimate_orientation,
    random_rotation,
    run_attitude_filter,
    with_spin,
)
from quadlib.constants import G0
from quadlib.fixedwing import (
    FixedWingNoise,
    aileron_roll,
    error_state_ukf,
    estimate_fixedwing_attitude,
    fixedwing_flight,
    fixedwing_samples,
    multiplicative_ekf,
    salmony_ekf,
)
from quadlib.quad import Quad3DParams, SensorNoise3D, figure_eight, quad3d_ukf_options, simulate_run3d
from quadlib.samples import Measurements
from quadlib.sim import imu_faults, imu_samples, vertical_sine

START, LENGTH = 10.0, 2.0  # default fault window [s]


def _cell(err, t, clean_peak, end, ok=True) -> str:
    after = t >= START
    peak = np.nanmax(err[after]) if np.isfinite(err[after]).any() else np.inf
    limit = 2.0 * clean_peak
    bad = np.flatnonzero((err > limit) | ~np.isfinite(err))
    bad = bad[t[bad] >= end]
    if bad.size == 0:
        recover = "0.0 s"
    elif bad[-1] == t.size - 1:
        recover = "never"
    else:
        recover = f"{t[bad[-1] + 1] - end:.1f} s"
    return f"{peak:7.2f} / {recover:>5}{'' if ok and np.isfinite(err).all() else ' !'}"


# --- 3D quadrotor: GPS and heading faults ------------------------------------------------------

def quad3d_column(kind: str):
    run = simulate_run3d(figure_eight(duration_s=90.0, period_s=10.0), SensorNoise3D(), np.random.default_rng(21))
    params = Quad3DParams()
    gps_sensor, mag_sensor = params.sensors()

    def horizontal_error(gps: Samples, mag: Samples, target=None):
        f = (ModelUKF(params.model(), run.truth[0], params.P0, 0.02, **quad3d_ukf_options()) if kind == "UKF"
             else ModelEKF(params.model(), run.truth[0], params.P0, 0.02))
        res = run_filter(f, run.t, run.u, [Measurements(gps_sensor, gps.t, gps.z),
                                           Measurements(mag_sensor, mag.t, mag.z)], gate_probability=0.99)
        return np.hypot(*(res.x[:, :2] - (run.truth[:, :2] if target is None else target)).T)

    clean_peak = horizontal_error(run.gps, run.mag)[run.t > 2.0].max()
    rng = np.random.default_rng(5)
    t = run.gps.t
    cells = {}
    for name, length in (("outage 5 s", 5.0), ("outage 10 s", 10.0), ("outage 20 s", 20.0),
                         ("outage 60 s", 60.0), ("stuck 10 s", 10.0)):
        z = run.gps.z.copy()
        window = (t >= START) & (t < START + length)
        z[window] = np.nan if name.startswith("outage") else z[np.flatnonzero(window)[0]]
        cells[name] = _cell(horizontal_error(Samples(t, z), run.mag), run.t, clean_peak, START + length)
    z = run.gps.z.copy()
    z[t >= START, 0] += 20.0  # the receiver jumps 20 m north for good: the filter should follow it
    jumped = run.truth[:, :2] + np.where(run.t[:, None] >= START, [20.0, 0.0], 0.0)
    cells["jump 20 m, persists"] = _cell(horizontal_error(Samples(t, z), run.mag, jumped), run.t, clean_peak, START)
    z = run.gps.z.copy()
    z[rng.random(t.size) < 0.3] = np.nan
    cells["30 % dropouts"] = _cell(horizontal_error(Samples(t, z), run.mag), run.t, clean_peak, START)
    for scale in (10.0, 100.0):
        z = run.gps.z.copy()
        hit = (rng.random(t.size) < 0.05) & (t >= START) & (t < START + 10.0)
        z[hit, :3] += rng.normal(0.0, scale * 0.7, (hit.sum(), 3))
        cells[f"spikes {scale:.0f}σ (5 % for 10 s)"] = _cell(horizontal_error(Samples(t, z), run.mag), run.t,
                                                              clean_peak, START + 10.0)
    cells["duplicated timestamps (every GPS fix twice)"] = _cell(
        horizontal_error(Samples(np.repeat(t, 2), np.repeat(run.gps.z, 2, axis=0)), run.mag), run.t, clean_peak, 0.0)
    mag = run.mag.z.copy()
    window = (run.mag.t >= START) & (run.mag.t < START + 10.0)
    mag[window] = mag[np.flatnonzero(window)[0]]
    cells["stuck magnetometer"] = _cell(horizontal_error(run.gps, Samples(run.mag.t, mag)), run.t, clean_peak,
                                        START + 10.0)
    swapped = t.copy()
    swapped[[40, 41]] = swapped[[41, 40]]
    try:
        horizontal_error(Samples(swapped, run.gps.z), run.mag)
        cells["out-of-order timestamp"] = "accepted"
    except ValueError as err:
        cells["out-of-order timestamp"] = "named error (" + str(err).split(":")[0] + ")"
    return cells


# --- attitude filters: IMU and magnetometer faults ------------------------------------------------

GYRO_RANGE = float(np.radians(2000.0))


def _kesten(name):
    return lambda noise, log: run_attitude_filter(FILTERS[name](noise), log).q_nb


def _orientation(noise, log):
    params = OrientationParams(gyro_sigma_rad_s=noise.gyro_sigma_rad_s, gyro_range_rad_s=noise.gyro_range_rad_s)
    return estimate_orientation(log, params=params).q


def attitude_column(estimate):
    """``estimate(noise, log) -> q_nb (N, 4)`` on Kesten's tumble at 250 Hz."""
    noise = AttitudeNoise(gyro_range_rad_s=GYRO_RANGE)
    base = random_rotation(30.0, 250.0, np.random.default_rng(3))
    rng = np.random.default_rng(7)
    clean_log = imu_samples(base, noise, np.random.default_rng(4), field_n=noise.field_n, mag_every=5)
    clean = np.degrees(attitude_error(estimate(noise, clean_log), base.q_nb))
    clean_peak = clean[base.t > 2.0].max()
    cells = {}
    for fault, (log, end) in imu_faults(clean_log, noise.field_n, noise.accel_sigma_m_s2, rng, START, LENGTH).items():
        q = estimate(noise, log)
        ok = np.abs(np.linalg.norm(q, axis=1) - 1).max() < 1e-9
        cells[fault] = _cell(np.degrees(attitude_error(q, base.q_nb)), base.t, clean_peak, end, ok)
    spin = with_spin(base, START, 1.0, 40.0)  # 40 rad/s for 1 s: the gyro clips at 34.9 rad/s
    log = imu_samples(spin, noise, np.random.default_rng(4), field_n=noise.field_n, mag_every=5)
    q = estimate(noise, log)
    cells["gyro saturated in a 40 rad/s spin (1 s)"] = _cell(np.degrees(attitude_error(q, spin.q_nb)), base.t,
                                                             clean_peak, START + 1.0)
    return cells


def fixedwing_column(factory):
    noise = FixedWingNoise(gyro_range_rad_s=GYRO_RANGE)
    flight = fixedwing_flight(rate_hz=50.0)
    clean_log = fixedwing_samples(flight, noise, np.random.default_rng(12))
    clean = np.degrees(attitude_error(estimate_fixedwing_attitude(clean_log, noise, factory).x[:, :4], flight.q_nb))
    clean_peak = clean[flight.t > 5.0].max()
    cells = {}
    faults = imu_faults(clean_log, [1.0, 0.0, 0.0], noise.accel_sigma_m_s2, np.random.default_rng(7), START, LENGTH)
    for fault, (log, end) in faults.items():
        x = estimate_fixedwing_attitude(log, noise, factory).x
        ok = np.abs(np.linalg.norm(x[:, :4], axis=1) - 1).max() < 1e-9
        cells[fault] = _cell(np.degrees(attitude_error(x[:, :4], flight.q_nb)), flight.t, clean_peak, end, ok)
    rolled = aileron_roll(flight, START, 45.0, turns=2)  # 45 rad/s for 0.28 s: the gyro clips at 34.9 rad/s
    x = estimate_fixedwing_attitude(fixedwing_samples(rolled, noise, np.random.default_rng(12)), noise, factory).x
    cells["gyro saturated in two 45 rad/s rolls"] = _cell(np.degrees(attitude_error(x[:, :4], rolled.q_nb)),
                                                          flight.t, clean_peak, START + 4 * np.pi / 45.0)
    return cells


def altitude_column():
    """Kesten's altitude KF: a vertical sine (±5 m, 20 s period), a_z at 250 Hz, baro at 25 Hz."""
    sigma_a, sigma_b = 0.06, 0.39
    rng = np.random.default_rng(9)
    t, s, a_z, samples = vertical_sine(60.0, rng, accel_sigma_m_s2=sigma_a, baro_sigma_m=sigma_b)
    dt, baro_t, baro = t[1] - t[0], samples.t, samples.z
    sensor = replace(baro_altitude_sensor(sigma_b), reset_after_s=1.0, stuck_samples=5)

    def error(z, acc=a_z, target=s):
        kf = LinearKF(altitude_model(sigma_a, 1e-5, 16 * G0), [0.0, 0.0, G0], np.diag([1.0, 0.1, 0.01]), dt)
        run = run_filter(kf, t, acc[:, None], [Measurements(sensor, baro_t, z[:, None])], gate_probability=0.99)
        return np.abs(run.x[:, 0] - target)

    clean_peak = error(baro)[t > 5.0].max()
    cells = {}
    window = (baro_t >= START) & (baro_t < START + 10.0)
    z = baro.copy()
    z[window] = np.nan
    cells["outage 10 s"] = _cell(error(z), t, clean_peak, START + 10.0)
    z = baro.copy()
    z[window] = z[np.flatnonzero(window)[0]]
    cells["stuck 10 s"] = _cell(error(z), t, clean_peak, START + 10.0)
    z = baro + np.where(baro_t >= START, 20.0, 0.0)
    cells["jump 20 m, persists"] = _cell(error(z, target=s + np.where(t >= START, 20.0, 0.0)), t, clean_peak,
                                              START)
    for scale in (10.0, 100.0):
        z = baro.copy()
        hit = (rng.random(z.size) < 0.05) & (baro_t >= START) & (baro_t < START + 10.0)
        z[hit] += rng.normal(0.0, scale * sigma_b, hit.sum())
        cells[f"spikes {scale:.0f}σ (5 % for 10 s)"] = _cell(error(z), t, clean_peak, START + 10.0)
    acc = a_z.copy()
    shock = (t >= START) & (t < START + 0.05)
    acc[shock] = np.clip(acc[shock] + 30 * G0, -16 * G0, 16 * G0)
    cells["30 g shock clipped at 16 g"] = _cell(error(baro, acc), t, clean_peak, START + 0.05)
    acc = a_z.copy()
    hit = rng.random(t.size) < 0.02
    acc[hit] += rng.normal(0.0, 20 * sigma_a, hit.sum())
    cells["accelerometer spikes 20σ (2 %)"] = _cell(error(baro, acc), t, clean_peak, t[-1])
    return cells


def main() -> None:
    start = time.perf_counter()
    columns = {"3D EKF [m]": quad3d_column("EKF"), "3D UKF [m]": quad3d_column("UKF")}
    long_run = simulate_run3d(figure_eight(duration_s=2000.0, period_s=10.0), SensorNoise3D(), np.random.default_rng(8))
    params = Quad3DParams()
    res = run_filter(ModelEKF(params.model(), long_run.truth[0], params.P0, 0.02), long_run.t, long_run.u,
                     [Measurements(s, x.t, x.z) for s, x in zip(params.sensors(), (long_run.gps, long_run.mag),
                                                                strict=True)], gate_probability=0.99)
    pd = all(np.linalg.eigvalsh(P).min() > 0 for P in res.P[::1000])
    columns["3D EKF [m]"][f"{long_run.t.size - 1} steps"] = (
        f"{np.hypot(*(res.x[:, :2] - long_run.truth[:, :2]).T).max():7.2f} / finite "
        f"{np.isfinite(res.x).all()}, P > 0 {pd}")
    for name in FILTERS:
        columns[f"Kesten {name} [°]"] = attitude_column(_kesten(name))
    columns["orientation MEKF [°]"] = attitude_column(_orientation)
    columns["fixed-wing EKF [°]"] = fixedwing_column(salmony_ekf)
    columns["fixed-wing MEKF [°]"] = fixedwing_column(multiplicative_ekf)
    columns["fixed-wing ES-UKF [°]"] = fixedwing_column(error_state_ukf)
    columns["altitude KF [m]"] = altitude_column()
    rows = list(dict.fromkeys(r for c in columns.values() for r in c))
    print("cell: peak error after the fault starts / time after it ends to stay within 2x the clean peak; "
          "! = non-finite or non-unit")
    print("| fault | " + " | ".join(columns) + " |")
    print("|---|" + "---|" * len(columns))
    for r in rows:
        print(f"| {r} | " + " | ".join(c.get(r, "n/a") for c in columns.values()) + " |")
    print(f"\n({time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
