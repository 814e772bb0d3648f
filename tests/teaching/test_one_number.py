"""Chapter 03's flight and the one-number filter behind its slider."""

import numpy as np
import pytest

from quadlib.teaching import ClimbFlight, OneNumberTrial, climb_flight, one_number_trial, plot_trial, show_trial
from quadlib.teaching.one_number import CHAPTER_SEED


def test_the_flight_follows_its_commands_and_gust():
    quiet = climb_flight(np.random.default_rng(0), sigma_q=1e-12, sigma_r=1e-12, gust_m=1.0)
    assert isinstance(quiet, ClimbFlight) and quiet.t.shape == quiet.truth.shape == quiet.z.shape == (401,)
    assert quiet.dt == pytest.approx(0.1) and quiet.t[-1] == pytest.approx(40.0)
    at = {s: quiet.truth[np.searchsorted(quiet.t, s)] for s in (0.0, 10.0, 21.9, 24.1, 30.0, 40.0)}
    assert at[0.0] == pytest.approx(2.0) and at[10.0] == pytest.approx(7.0)  # 5 s at 1 m/s
    assert at[21.9] == pytest.approx(7.0) and at[24.1] == pytest.approx(8.0, abs=3e-3)  # the gust adds 1 m
    assert at[40.0] == pytest.approx(5.0, abs=3e-3)  # 6 s at -0.5 m/s
    np.testing.assert_allclose(quiet.z, quiet.truth, atol=1e-9)
    assert np.sum(quiet.gust_rate * quiet.dt) == pytest.approx(1.0, abs=3e-3)


def test_the_flight_noise_has_the_stated_sizes_and_comes_from_the_rng():
    f = climb_flight(np.random.default_rng(1), sigma_q=0.05, sigma_r=0.4, gust_m=0.0, duration_s=2000.0)
    steps = np.diff(f.truth) - f.u[:-1] * f.dt
    assert np.std(steps) == pytest.approx(0.05, rel=0.03)
    assert np.std(f.z - f.truth) == pytest.approx(0.4, rel=0.03)
    a, b = climb_flight(np.random.default_rng(7)), climb_flight(np.random.default_rng(7))
    assert np.array_equal(a.z, b.z) and not np.array_equal(a.z, climb_flight(np.random.default_rng(8)).z)


def test_the_trial_is_the_one_number_kalman_filter_on_the_chapters_flight():
    trial = one_number_trial(0.05, 0.2, x0=1.0, sigma0=0.7)
    f = climb_flight(np.random.default_rng(CHAPTER_SEED))
    assert isinstance(trial, OneNumberTrial) and np.array_equal(trial.flight.z, f.z)
    Q, R = 0.05**2, 0.2**2
    x, P = 1.0, 0.7**2
    for k in range(f.t.size):
        if k > 0:
            x, P = x + f.u[k - 1] * f.dt, P + Q
        K = P / (P + R)
        x, P = x + K * (f.z[k] - x), (1 - K) * P
        assert trial.x[k] == pytest.approx(x, abs=1e-12) and trial.P[k] == pytest.approx(P, rel=1e-12)
        assert trial.K[k] == pytest.approx(K, rel=1e-12)
    P_bar = (Q + np.sqrt(Q**2 + 4 * Q * R)) / 2  # the steady state the chapter derives
    assert trial.K[-1] == pytest.approx(P_bar / (P_bar + R), rel=1e-9)


def test_only_the_ratios_set_the_estimate():
    a, b = one_number_trial(0.03, 0.3, sigma0=0.5), one_number_trial(0.06, 0.6, sigma0=1.0)
    np.testing.assert_allclose(b.x, a.x, atol=1e-12)
    np.testing.assert_allclose(b.P, 4 * a.P, rtol=1e-12)


def test_lies_cost_accuracy_and_honesty():
    honest, deaf, jittery = one_number_trial(0.03, 0.3), one_number_trial(0.003, 0.3), one_number_trial(0.3, 0.3)
    assert honest.rmse < min(deaf.rmse, jittery.rmse)
    assert deaf.inside < 0.5 < 0.85 < honest.inside < jittery.inside
    sure_wrong, unsure_wrong = one_number_trial(0.03, 0.3, 0.0, 0.05), one_number_trial(0.03, 0.3, 0.0, 100.0)
    assert abs(sure_wrong.error[5]) > 1.0 > 0.5 > abs(unsure_wrong.error[5])


def test_the_trial_prints_and_draws_on_its_own_figure(capsys):
    import matplotlib.pyplot as plt

    plt.close("all")
    trial = one_number_trial(0.01, 1.0, x0=0.0, sigma0=0.05)
    assert "σ_q = 0.01 m" in trial.summary() and "RMSE" in trial.summary()
    fig = plot_trial(trial)
    assert len(fig.axes) == 2 and all(ax.get_lines() for ax in fig.axes)
    assert plt.get_fignums() == []
    show_trial(trial)
    assert capsys.readouterr().out.splitlines()[0] == trial.summary()  # then the figure


def test_bad_arguments_are_named():
    with pytest.raises(TypeError, match="rng"):
        climb_flight(3)
    with pytest.raises(ValueError, match="duration_s: expected at least two steps"):
        climb_flight(np.random.default_rng(0), duration_s=0.1)
    with pytest.raises(ValueError, match="sigma_q"):
        one_number_trial(0.0, 0.3)
    with pytest.raises(ValueError, match="seed"):
        one_number_trial(0.03, 0.3, seed=-1)
