from dataclasses import dataclass

import numpy as np
import pytest

from quadlib.validation import (
    as_bool,
    as_count,
    as_covariance,
    as_finite_array,
    as_matrix,
    as_optional,
    as_positive,
    as_probability,
    as_vector,
    check_fields,
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


def test_as_count_returns_an_int_within_its_bounds():
    assert as_count("n", np.int64(4)) == 4 and type(as_count("n", np.int64(4))) is int
    assert as_count("shift", -100, low=-100, high=100) == -100 and as_count("shift", 100, low=-100, high=100) == 100


@pytest.mark.parametrize("bad, low, high, message", [
    (0, 1, None, "n: expected an int >= 1, got 0"), (True, 0, None, "n: expected an int >= 0, got True"),
    (2.0, 1, None, "n: expected an int >= 1, got 2.0"), ("3", 1, None, "n: expected an int >= 1, got '3'"),
    (0, 1, 5, r"n: expected an int in \[1, 5\], got 0"), (6, 1, 5, r"n: expected an int in \[1, 5\], got 6"),
    (True, 0, 5, r"n: expected an int in \[0, 5\], got True"), (1.5, 1, 5, r"n: expected an int in \[1, 5\], got 1.5"),
])
def test_as_count_rejects_naming_the_argument_and_its_bounds(bad, low, high, message):
    with pytest.raises(ValueError, match=f"^{message}$"):
        as_count("n", bad, low, high=high)


@dataclass(frozen=True)
class _Flags:
    n: object = 3
    on: object = True
    every: object = None

    def __post_init__(self):
        check_fields(self, {"n": "count", "on": "bool", "every": "optional count"})


@pytest.mark.parametrize("field, bad, check", [("n", 0, as_count), ("n", 2.0, as_count), ("n", True, as_count),
                                               ("n", "3", as_count), ("on", 1, as_bool), ("on", "yes", as_bool),
                                               ("on", None, as_bool)])
def test_count_and_bool_fields_are_as_count_and_as_bool(field, bad, check):
    with pytest.raises((TypeError, ValueError)) as direct:
        check(f"_Flags.{field}", bad)
    with pytest.raises(direct.type) as checked:
        _Flags(**{field: bad})
    assert str(checked.value) == str(direct.value)


def test_count_and_bool_fields_store_what_as_count_and_as_bool_return():
    flags = _Flags(n=np.int64(4), on=np.bool_(False), every=2)
    assert type(flags.n) is int and flags.on is False and flags.every == 2
    assert _Flags(every=None).every is None
    with pytest.raises(ValueError, match=r"^_Flags.every: expected an int >= 1 or None, got 0$"):
        _Flags(every=0)


def test_as_optional_passes_none_and_says_so_when_it_refuses():
    assert as_optional(as_count, "n", None, low=2) is None
    assert as_optional(as_count, "n", 3, low=2) == 3
    with pytest.raises(ValueError, match=r"^n: expected an int >= 2 or None, got 1$"):
        as_optional(as_count, "n", 1, low=2)
    with pytest.raises(TypeError, match=r"^flag: expected True or False or None, got 'yes'$"):
        as_optional(as_bool, "flag", "yes")


def test_a_declination_outside_half_a_turn_is_refused_as_degrees():
    from quadlib.attitude.orientation import estimate_orientation
    from quadlib.validation import as_angle

    assert as_angle("declination_rad", -np.pi) == -np.pi
    with pytest.raises(ValueError, match=r"declination_rad: expected radians within \[-π, π\], got 3.3 \(degrees\?"):
        as_angle("declination_rad", 3.3)
    t = np.arange(50) * 0.01
    with pytest.raises(ValueError, match="declination_rad: expected radians"):
        estimate_orientation(t, np.zeros((50, 3)), np.tile([0.0, 0.0, -9.81], (50, 1)), declination_rad=10.0)
