import numpy as np
import pytest

from quadlib.teaching import show_source, span


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
