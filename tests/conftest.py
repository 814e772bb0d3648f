import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")


def _assert_same_run(compiled, readable):
    """Two FilterRuns of the same filter agree: states and covariances to 1e-10, the same flags,
    innovations to 1e-9 relative or of the sensor's largest (a small innovation is the difference of
    two large numbers, gravity's of two near 9.8 m/s²: after gravity's resets on the fixed-wing
    flight, one in a thousand differs by 1.8e-10 while the state agrees to 1e-10), NIS to 1e-8
    relative (``yᵀ S⁻¹ y`` of a small innovation over a small ``S``: on a CPU whose compiled code
    fuses multiply-adds, one NIS in a thousand of the fixed-wing EKF differs by 3e-9 of itself while
    its state agrees to 5e-12), each S to 1e-9 of its largest element (an element near zero beside
    large ones carries their rounding, not its own)."""
    np.testing.assert_allclose(compiled.x, readable.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(compiled.P, readable.P, rtol=0, atol=1e-10)
    assert np.array_equal(compiled.held_input, readable.held_input)
    assert list(compiled.sensors) == list(readable.sensors)
    for name, a in compiled.sensors.items():
        b = readable.sensors[name]
        np.testing.assert_array_equal(a.t, b.t)
        for flag in ("used", "rejected", "reset", "missing", "duplicate"):
            assert np.array_equal(getattr(a, flag), getattr(b, flag)), (name, flag)
        largest = np.nanmax(np.abs(b.innovation), initial=0.0)
        np.testing.assert_allclose(a.innovation, b.innovation, rtol=1e-9, atol=1e-10 + 1e-9 * largest,
                                   err_msg=f"{name}.innovation")
        np.testing.assert_allclose(a.nis, b.nis, rtol=1e-8, atol=1e-10, err_msg=f"{name}.nis")
        assert np.array_equal(np.isnan(a.S), np.isnan(b.S)), f"{name}.S: NaN in different places"
        if a.S.size:
            scale = np.nan_to_num(np.abs(b.S)).max(axis=(1, 2), keepdims=True)
            excess = np.nan_to_num(np.abs(a.S - b.S)) - (1e-10 + 1e-9 * scale)
            assert excess.max() <= 0, f"{name}.S: differs by up to {np.nanmax(np.abs(a.S - b.S)):.3g}"


@pytest.fixture
def assert_same_run():
    """The check that a compiled filter gives what its readable twin gives (see ``_assert_same_run``)."""
    return _assert_same_run
