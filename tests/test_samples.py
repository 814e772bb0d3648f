"""Cutting a sample stream to a time window: both ends included, to the times' precision."""

import numpy as np
import pytest

from quadlib import Measurements, Samples
from quadlib.model import Sensor


def _sensor_with_context():
    return Sensor("speed", ("v [m/s]",), h=lambda x, c: x[:1] * c[0], R=np.array([[0.01]]),
                  H=lambda x, c: np.array([[c[0], 0.0]]), context_names=("scale",))


def test_samples_between_keeps_both_ends_and_what_lies_within_rounding():
    t = np.array([0.0, 0.1, 0.2, 0.30000000000000004, 0.4])
    cut = Samples(t, np.arange(5.0)).between(0.1, 0.3)
    assert cut.t.tolist() == [0.1, 0.2, 0.30000000000000004]
    assert cut.z.tolist() == [1.0, 2.0, 3.0]


def test_measurements_between_cuts_the_context_with_the_samples():
    m = Measurements(_sensor_with_context(), [0.0, 1.0, 2.0, 3.0], [[1.0], [2.0], [3.0], [4.0]],
                     context=[[1.0], [2.0], [3.0], [4.0]])
    cut = m.between(1.0, 2.5)
    assert cut.sensor is m.sensor
    assert cut.t.tolist() == [1.0, 2.0] and cut.z[:, 0].tolist() == [2.0, 3.0]
    assert cut.context[:, 0].tolist() == [2.0, 3.0]
    assert m.between(5.0, 6.0).t.size == 0


@pytest.mark.parametrize(("arg", "value"), [("start_s", "0"), ("end_s", float("nan")), ("start_s", None)])
def test_a_bad_window_is_named(arg, value):
    bounds = {"start_s": 0.0, "end_s": 1.0, arg: value}
    with pytest.raises((TypeError, ValueError), match=f"{arg}: expected"):
        Samples([0.0, 0.5], [1.0, 2.0]).between(**bounds)
