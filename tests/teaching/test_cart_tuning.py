"""The cart's Q and R trial (chapter 06's slider): what it measures, and the scenario it runs."""

import numpy as np
import pytest

from quadlib.teaching import cart_push_input, cart_tuning_trial, plot_trial
from quadlib.teaching.cart_tuning import CART_TRUE_SIGMAS


def test_the_cart_is_pushed_coasts_is_braked_and_rests():
    t = np.array([0.0, 3.9, 4.0, 13.9, 14.0, 18.9, 19.0, 30.0])
    np.testing.assert_allclose(cart_push_input(t)[:, 0], [0.5, 0.5, 0.0, 0.0, -0.4, -0.4, 0.0, 0.0])
    assert cart_push_input(t).shape == (8, 1)
    with pytest.raises(ValueError, match="t: expected strictly increasing"):
        cart_push_input([0.0, 2.0, 1.0])


def test_the_true_sigmas_give_a_consistent_filter_and_wrong_ones_are_named():
    right = cart_tuning_trial(*CART_TRUE_SIGMAS)
    small_q = cart_tuning_trial(CART_TRUE_SIGMAS[0] / 10, *CART_TRUE_SIGMAS[1:])
    big_r = cart_tuning_trial(CART_TRUE_SIGMAS[0], 5 * CART_TRUE_SIGMAS[1], 5 * CART_TRUE_SIGMAS[2])
    sharp_position = cart_tuning_trial(CART_TRUE_SIGMAS[0], CART_TRUE_SIGMAS[1] / 3, CART_TRUE_SIGMAS[2])
    assert right.verdict == "consistent"
    assert right.nis_band[0] < right.anis_position < right.nis_band[1]
    assert right.nis_band[0] < right.anis_speed < right.nis_band[1]
    assert small_q.verdict == "over-confident" and small_q.anis_speed > right.nis_band[1]
    assert big_r.verdict == "pessimistic" and max(big_r.anis_position, big_r.anis_speed) < right.nis_band[0]
    # a position sensor believed better than it is: its own NIS leaves the band, the odometer's does not
    assert sharp_position.anis_position > 3 * right.nis_band[1]
    assert right.nis_band[0] < sharp_position.anis_speed < right.nis_band[1]
    assert right.rmse_p < min(small_q.rmse_p, big_r.rmse_p)


def test_scaling_every_sigma_keeps_the_estimate_and_scales_the_claimed_uncertainty():
    once, twice = cart_tuning_trial(*CART_TRUE_SIGMAS), cart_tuning_trial(*(2 * s for s in CART_TRUE_SIGMAS))
    assert twice.rmse_p == pytest.approx(once.rmse_p, rel=0.05)
    assert twice.anees == pytest.approx(once.anees / 4, rel=0.25)
    assert twice.verdict == "pessimistic"


def test_a_cart_trial_is_reproducible_has_one_value_per_time_and_draws_three_panels():
    a, b, c = (cart_tuning_trial(0.2, 0.5, seed=s) for s in (3, 3, 4))
    assert np.array_equal(a.mean_nees, b.mean_nees) and not np.array_equal(a.mean_nees, c.mean_nees)
    assert a.mean_nees.shape == a.t.shape and a.t.size == 301
    assert a.mean_nis_position.shape == a.t_position.shape == (31,)
    assert a.mean_nis_speed.shape == a.t_speed.shape == (151,)
    assert a.summary().startswith("told σ_w = 0.2 m/s², σ_p = 0.5 m, σ_v = 0.1 m/s, 20 runs")
    assert a.summary().endswith(a.verdict)
    fig = plot_trial(cart_tuning_trial(0.2, 0.5, n_flights=3))
    assert len(fig.axes) == 3 and all(ax.get_lines() for ax in fig.axes) and fig.legends
