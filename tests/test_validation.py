import numpy as np
import pytest

from quadlib.validation import (
    as_bool,
    as_covariance,
    as_finite_array,
    as_matrix,
    as_positive,
    as_probability,
    as_vector,
)


def test_as_vector_accepts_column_and_scalar():
    assert as_vector("x", [[1.0], [2.0]]).shape == (2,)
    assert as_vector("x", 3.0, 1).tolist() == [3.0]


@pytest.mark.parametrize(
    "value, size, message",
    [
        ([1.0, 2.0], 3, r"x: expected shape \(3,\), got \(2,\)"),
        (np.ones((2, 2)), None, r"x: expected a vector, got shape \(2, 2\)"),
        ([1.0, np.nan], 2, r"x: expected finite values, got 1 NaN"),
        ([np.inf, np.nan], 2, r"x: expected finite values, got 1 NaN and 1 inf"),
    ],
)
def test_as_vector_errors_name_argument_expected_and_given(value, size, message):
    with pytest.raises(ValueError, match=message):
        as_vector("x", value, size)


def test_non_numeric_is_type_error():
    with pytest.raises(TypeError, match="x: expected numbers"):
        as_vector("x", ["a", "b"])


def test_as_matrix_shape():
    with pytest.raises(ValueError, match=r"F: expected shape \(2, 2\), got \(2, 3\)"):
        as_matrix("F", np.ones((2, 3)), (2, 2))


def test_as_covariance_accepts_psd_and_scalar():
    assert as_covariance("P", [[2.0, 1.0], [1.0, 2.0]], 2).shape == (2, 2)
    assert as_covariance("R", 0.25, 1).tolist() == [[0.25]]
    assert as_covariance("P", np.zeros((2, 2)), 2).sum() == 0.0  # semi-definite is allowed


def test_as_covariance_rejects_asymmetric_and_indefinite():
    with pytest.raises(ValueError, match="P: expected a symmetric covariance matrix"):
        as_covariance("P", [[1.0, 0.5], [0.0, 1.0]], 2)
    with pytest.raises(ValueError, match=r"P: expected a positive semi-definite .* smallest eigenvalue -1"):
        as_covariance("P", [[1.0, 2.0], [2.0, 1.0]], 2)
    with pytest.raises(ValueError, match=r"R: expected shape \(2, 2\), got \(3, 3\)"):
        as_covariance("R", np.eye(3), 2)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.inf, np.nan])
def test_as_positive_rejects(bad):
    with pytest.raises(ValueError, match="dt: expected a finite number > 0"):
        as_positive("dt", bad)


def test_as_positive_types():
    assert as_positive("dt", 0, allow_zero=True) == 0.0
    with pytest.raises(TypeError, match="dt: expected a real number"):
        as_positive("dt", [0.1])
    with pytest.raises(TypeError, match="dt: expected a real number"):
        as_positive("dt", True)


def test_as_probability():
    assert as_probability("p", 0.5) == 0.5
    assert as_probability("p", 1.0, open_interval=False) == 1.0
    with pytest.raises(ValueError, match=r"p: expected a number in \(0, 1\), got 1.0"):
        as_probability("p", 1.0)


def test_as_finite_array_ndim():
    with pytest.raises(ValueError, match=r"t: expected a 1-D array, got shape \(2, 2\)"):
        as_finite_array("t", np.ones((2, 2)), ndim=1)


def test_as_times():
    from quadlib.validation import as_times
    assert as_times("t", [0.0, 0.5]).tolist() == [0.0, 0.5]
    with pytest.raises(ValueError, match="t: expected strictly increasing times"):
        as_times("t", [0.0, 0.0])
    with pytest.raises(ValueError, match="t: expected at least one time"):
        as_times("t", [])


def test_as_bool_accepts_python_and_numpy_bools():
    assert as_bool("flag", True) is True
    assert as_bool("flag", np.bool_(False)) is False


@pytest.mark.parametrize("bad, shown", [(1, "1"), (0, "0"), ("yes", "'yes'"), (None, "None"),
                                        (np.array([True]), r"array\(\[ True\]\)")])
def test_as_bool_rejects_other_values_naming_the_argument(bad, shown):
    with pytest.raises(TypeError, match=f"^compiled: expected True or False, got {shown}$"):
        as_bool("compiled", bad)
