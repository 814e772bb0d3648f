import numpy as np
import pytest

from quadlib.model import Model, Sensor
from quadlib.quad.height import height_model, range_sensor


def _identity_model(**kw):
    base = dict(state_names=("a",), input_names=(), g=lambda x, u, dt: x, G=lambda x, u, dt: np.eye(1),
                Q=lambda dt: np.eye(1))
    base.update(kw)
    return Model(**base)


def test_model_dimensions_and_step():
    m = height_model(0.1)
    assert (m.dim_x, m.dim_u) == (1, 1)
    assert m.step([2.0], [0.5], 0.2).tolist() == pytest.approx([2.1])


def test_model_step_checks_every_argument():
    m = height_model(0.1)
    with pytest.raises(ValueError, match=r"x: expected shape \(1,\), got \(2,\)"):
        m.step([1.0, 2.0], [0.0], 0.1)
    with pytest.raises(ValueError, match=r"u: expected shape \(1,\), got None"):
        m.step([1.0], None, 0.1)
    with pytest.raises(ValueError, match="dt: expected a finite number > 0, got -0.1"):
        m.step([1.0], [0.0], -0.1)


def test_model_rejects_bad_descriptions():
    with pytest.raises(TypeError, match="Model.state_names: expected a sequence of str"):
        _identity_model(state_names="abc")
    with pytest.raises(ValueError, match="Model.state_names: expected unique names"):
        _identity_model(state_names=("a", "a"))
    with pytest.raises(TypeError, match="Model.G: expected a callable"):
        _identity_model(G=np.eye(1))


def test_model_is_frozen():
    m = _identity_model()
    with pytest.raises(AttributeError):
        m.g = None


def test_sensor_checks_R():
    with pytest.raises(ValueError, match=r"Sensor\('r'\).R: expected shape \(1, 1\), got \(2, 2\)"):
        Sensor("r", ("z",), h=lambda x: x, H=lambda x: np.eye(1), R=np.eye(2))
    with pytest.raises(ValueError, match=r"Sensor\('r'\).R: expected a positive semi-definite"):
        Sensor("r", ("z",), h=lambda x: x, H=lambda x: np.eye(1), R=[[-1.0]])
    s = range_sensor(0.3, rate_hz=10)
    assert s.R[0, 0] == pytest.approx(0.09)  # sigma squared, not sigma
    assert not s.R.flags.writeable


def test_sensor_measurement_check_names_sensor():
    s = range_sensor(0.3)
    with pytest.raises(ValueError, match=r"z \(range\): expected finite values"):
        s.check_measurement([np.nan])


def test_height_model_noise_arguments_validated():
    with pytest.raises(ValueError, match="velocity_sigma_m_s: expected a finite number > 0"):
        height_model(0.0)
    with pytest.raises(ValueError, match="sigma_m: expected a finite number > 0"):
        range_sensor(-1.0)


def test_height_model_Q_scales_with_dt_squared():
    m = height_model(0.2)
    assert m.Q(0.5)[0, 0] == pytest.approx((0.2 * 0.5) ** 2)


def test_check_inputs_series():
    m = height_model(0.1)
    assert m.check_inputs([0.1, 0.2], 2).shape == (2, 1)
    with pytest.raises(ValueError, match=r"u: expected shape \(3, 1\), got None"):
        m.check_inputs(None, 3)
    with pytest.raises(ValueError, match=r"u: expected shape \(3, 1\), got \(2, 1\)"):
        m.check_inputs([[0.1], [0.2]], 3)
    assert _identity_model().check_inputs(None, 4).shape == (4, 0)
