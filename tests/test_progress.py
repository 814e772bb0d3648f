"""Progress bars: drawn when switched on, and absent from every test run (and so from stored outputs)."""


import pytest

from quadlib.progress import ENV_VAR, progress, progress_enabled


def test_the_test_suite_runs_without_bars():
    assert not progress_enabled()
    items = [1, 2, 3]
    assert progress(items, "loop") is items


def test_a_bar_yields_every_item_in_order_when_switched_on(monkeypatch):
    monkeypatch.setenv(ENV_VAR, "on")
    assert progress_enabled()
    bar = progress(iter(range(5)), "loop", total=5)
    assert bar is not None and not isinstance(bar, range)
    assert list(bar) == [0, 1, 2, 3, 4]


@pytest.mark.parametrize("value", ["off", "OFF", " off "])
def test_off_in_any_case_switches_bars_off(monkeypatch, value):
    monkeypatch.setenv(ENV_VAR, value)
    assert not progress_enabled()
