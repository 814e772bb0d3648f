"""The sliders' callbacks: each trial measures what its chapter says, and the sliders drive them."""

import ipywidgets as widgets
import numpy as np
import pytest

from quadlib.teaching.tuning import (
    complementary_trial,
    gate_trial,
    kf_tuning_trial,
    plot_trial,
    show_trial,
    tuning_sliders,
)


def test_the_true_noise_gives_a_consistent_kf_and_a_tenth_of_it_an_over_confident_one():
    right, small_q, big_r = kf_tuning_trial(0.3, 0.1), kf_tuning_trial(0.03, 0.1), kf_tuning_trial(0.3, 1.0)
    assert right.verdict == "consistent" and right.nees_band[0] < right.anees < right.nees_band[1]
    assert small_q.verdict == "over-confident" and small_q.anees > 5 * right.anees
    assert big_r.verdict == "pessimistic" and big_r.anis < right.nis_band[0]
    assert right.rmse_z < min(small_q.rmse_z, big_r.rmse_z)
    assert right.mean_nees.shape == right.t.shape and right.mean_nis.shape == right.t_range.shape


def test_a_kf_trial_is_reproducible_from_its_seed_and_changes_with_it():
    a, b, c = kf_tuning_trial(0.3, 0.1, seed=4), kf_tuning_trial(0.3, 0.1, seed=4), kf_tuning_trial(0.3, 0.1, seed=5)
    assert np.array_equal(a.mean_nees, b.mean_nees) and not np.array_equal(a.mean_nees, c.mean_nees)


def test_the_complementary_filter_trades_noise_against_acceleration_errors():
    fast = {tau: complementary_trial(tau).rms_deg[1] for tau in (0.05, 2.0, 50.0)}
    assert fast[2.0] < fast[0.05], "a very short τ follows the accelerometer through every acceleration"
    biased = {tau: complementary_trial(tau, "slow", gyro_bias=True).rms_deg.max() for tau in (1.0, 50.0)}
    assert biased[1.0] < biased[50.0], "a biased gyro needs a short τ"


def test_a_gate_trades_caught_outliers_against_lost_good_samples():
    off, loose, tight = gate_trial(None), gate_trial(0.9), gate_trial(0.9999)
    assert off.caught == 0.0 and off.good_lost == 0.0
    assert loose.caught > tight.caught > 0.3
    assert loose.good_lost > tight.good_lost
    assert max(loose.rmse_y, tight.rmse_y) < off.rmse_y / 2
    assert tight.anees < off.anees / 3


def test_show_trial_prints_the_summary(capsys):
    trial = gate_trial(0.999, n_flights=4)
    show_trial(trial)
    assert capsys.readouterr().out.strip() == trial.summary()
    assert plot_trial(trial) is None
    assert len(plot_trial(kf_tuning_trial(0.3, 0.1, n_flights=3)).axes) == 2


def test_a_trial_draws_on_its_own_figure_and_leaves_pyplot_alone():
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    plt.close("all")
    fig = plot_trial(complementary_trial(0.5))
    assert isinstance(fig, Figure) and len(fig.axes) == 2 and fig.axes[0].get_lines()
    assert plt.get_fignums() == []  # nothing registered with pyplot, so no thread can draw on it by mistake


def test_a_chapters_own_record_is_a_trial():
    class Coin:
        def summary(self):
            return "heads"

        def draw(self, fig):
            fig.subplots().plot([0, 1], [1, 0])

    assert plot_trial(Coin()).axes[0].get_lines()
    with pytest.raises(TypeError, match="trial: expected a trial record with summary"):
        show_trial(object())


def test_sliders_rerun_the_trial_with_the_values_set():
    seen = []

    def trial(q, gate):
        seen.append((q, gate))
        return gate_trial(None, n_flights=2)

    panel = tuning_sliders(trial, q=(0.01, 1.0), gate=[None, 0.99])
    q_slider, gate_slider = panel.children[:2]
    assert isinstance(q_slider, widgets.FloatLogSlider) and q_slider.value == pytest.approx(0.1)
    assert isinstance(gate_slider, widgets.SelectionSlider) and gate_slider.value is None
    gate_slider.value = 0.99
    assert seen[-1] == (pytest.approx(0.1), 0.99)


def test_on_off_and_named_choices_get_checkboxes_and_buttons_with_readable_labels():
    panel = tuning_sliders(lambda tau, flight, gyro_bias: gate_trial(None, n_flights=2), tau=(0.05, 50.0),
                           flight=["fast", "slow"], gyro_bias=[False, True])
    tau, flight, bias = panel.children[:3]
    assert isinstance(tau, widgets.FloatLogSlider) and tau.description == "time constant τ [s]"
    assert isinstance(flight, widgets.ToggleButtons) and flight.value == "fast"
    assert isinstance(bias, widgets.Checkbox) and bias.value is False and bias.description == "gyro bias"


@pytest.mark.parametrize("spec", [(1.0, 0.5), (0.0, 1.0), [], "ab", (1.0, 2.0, 3.0)])
def test_a_malformed_slider_is_named(spec):
    with pytest.raises(ValueError, match="q: expected"):
        tuning_sliders(kf_tuning_trial, q=spec)
