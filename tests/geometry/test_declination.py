"""The World Magnetic Model's declination: against PX4's own lookup, its signs by place, its dates."""

import datetime

import numpy as np
import pytest
from pygeomag import decimal_year_from_date

from quadlib.data import load_ulog
from quadlib.geometry import model_declination_rad

UTC = datetime.UTC


def test_it_agrees_with_the_declination_px4_looked_up_and_saved():
    """PX4 v1.15 looked the declination up from its GPS position (EKF2_DECL_TYPE 7) and saved it:
    3.32° at Zürich in March 2024; the model gives 3.43°."""
    log = load_ulog("px4/sample_px4_events.ulg")
    assert log.parameters["EKF2_DECL_TYPE"] == 7
    assert np.degrees(log.model_declination_rad) == pytest.approx(np.degrees(log.mag_declination_rad), abs=0.2)


def test_its_sign_is_east_of_true_north():
    """Magnetic north lies west of true north in the eastern United States, east of it in Zürich."""
    when = datetime.datetime(2015, 6, 11, tzinfo=UTC)
    assert np.degrees(model_declination_rad([40.47, -86.97, 200.0], when)) == pytest.approx(-4.1, abs=0.3)
    assert np.degrees(model_declination_rad([47.40, 8.55, 490.0], when)) == pytest.approx(2.3, abs=0.5)


def test_it_moves_with_the_years_and_each_epoch_continues_the_last():
    place = [40.47, -86.97, 200.0]
    by_year = [np.degrees(model_declination_rad(place, datetime.datetime(y, 1, 1, tzinfo=UTC)))
               for y in range(2010, 2030)]
    steps = np.diff(by_year)
    assert np.all(steps < 0) and np.all(steps > -0.2)  # drifting west by about 0.1° a year, no jump at an epoch
    assert decimal_year_from_date(datetime.datetime(2015, 7, 2, 12, tzinfo=UTC)) == pytest.approx(2015.5, abs=1e-2)


def test_bad_arguments_are_named():
    when = datetime.datetime(2020, 1, 1, tzinfo=UTC)
    with pytest.raises(ValueError, match="lla: expected latitudes in \\[-90, 90\\]"):
        model_declination_rad([95.0, 0.0, 0.0], when)
    with pytest.raises(ValueError, match="lla: expected latitudes in .* longitudes in \\[-180, 180\\]"):
        model_declination_rad([0.0, 200.0, 0.0], when)
    with pytest.raises(ValueError, match="lla: expected one point of shape \\(3,\\)"):
        model_declination_rad([[0.0, 0.0, 0.0]] * 2, when)
    with pytest.raises(ValueError, match="when: expected a date in 2010–2029.*got 2005-01-01"):
        model_declination_rad([0.0, 0.0, 0.0], datetime.datetime(2005, 1, 1, tzinfo=UTC))
    with pytest.raises(TypeError, match="when: expected a datetime"):
        model_declination_rad([0.0, 0.0, 0.0], 2020.0)
