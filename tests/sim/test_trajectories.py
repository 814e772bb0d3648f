import numpy as np
import pytest

from quadlib.sim.trajectories import piecewise_constant


def test_piecewise_constant_switches_at_breakpoints():
    t = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 3.0])
    np.testing.assert_array_equal(piecewise_constant(t, [0.5, 1.5, 2.5], [1.0, -1.0, 0.0]),
                                  [0.0, 1.0, 1.0, -1.0, -1.0, 0.0])


def test_piecewise_constant_names_bad_arguments():
    with pytest.raises(ValueError, match="breakpoints: expected strictly increasing"):
        piecewise_constant([0.0], [1.0, 1.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="values: expected one value per breakpoint \\(2\\), got 1"):
        piecewise_constant([0.0], [1.0, 2.0], [1.0])
