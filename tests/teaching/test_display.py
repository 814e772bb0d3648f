import numpy as np
import pytest

from quadlib.teaching import rounding, show_source, span


def test_span_formats_both_ends():
    assert span([2.86, 4.23, 6.87]) == "2.9–6.9"
    assert span(np.array([0.06, 0.09]), ".0%") == "6%–9%"


def test_span_collapses_ends_that_print_the_same():
    assert span([2.86, 2.88]) == "2.9"
    assert span([0.009], ".3f") == "0.009"


def test_span_rejects_an_empty_sequence_and_a_bad_spec():
    with pytest.raises(ValueError, match="values: expected at least one number"):
        span([])
    with pytest.raises(ValueError, match="spec: expected a float format"):
        span([1.0], "d")


def test_show_source_names_the_object():
    assert show_source(span).data.startswith("`quadlib.teaching.display.span`")


def test_rounding_hides_the_last_digits_and_shows_a_real_difference():
    assert rounding(4.4e-16) == rounding(-6.7e-16) == "< 1e-12"
    assert rounding(np.float64(2.4e-6)) == "2.4e-06"
    assert rounding(3e-9, bound=1e-8) == "< 1e-08"
    assert rounding(1e-12) == "1.0e-12"  # the bound itself is not below the bound
    with pytest.raises(ValueError, match="value: expected one number"):
        rounding([1e-16, 1e-16])
    with pytest.raises(ValueError, match="bound: expected a positive number"):
        rounding(1e-16, bound=0.0)
