"""Where magnetic north is, at a place and a date: the World Magnetic Model's declination.

A magnetometer finds magnetic north; true north is the declination away from it, which depends on
where and when the vehicle flew (about −4° in Indiana in 2015, +3.4° in Zürich in 2024, tens of
degrees at high latitudes). The World Magnetic Model (NOAA and the British Geological Survey; its
coefficients are public domain) gives it to about half a degree away from the poles. Its
coefficients come with pygeomag, for each five-year epoch from 2010 to 2030.
"""

from __future__ import annotations

import datetime

import numpy as np

from quadlib.validation import as_finite_number

__all__ = ["model_declination_rad"]

_FIRST_YEAR, _END_YEAR = 2010, 2030  # the epochs pygeomag holds: 2010, 2015, 2020, 2025


def decimal_year(when: datetime.datetime) -> float:
    """``when`` (UTC) as a year with its fraction, as the model takes it: 2015-07-02 is about 2015.5."""
    start = datetime.datetime(when.year, 1, 1, tzinfo=when.tzinfo)
    end = datetime.datetime(when.year + 1, 1, 1, tzinfo=when.tzinfo)
    return when.year + (when - start) / (end - start)


def model_declination_rad(latitude_deg: float, longitude_deg: float, altitude_m: float,
                          when: datetime.datetime) -> float:
    """The World Magnetic Model's declination [rad], east of true north, at a place and a time.

    Parameters
    ----------
    latitude_deg, longitude_deg : float
        Geodetic latitude in [−90, 90] and longitude in [−180, 180] [deg].
    altitude_m : float
        Height above mean sea level [m] (the declination barely changes with it near the ground).
    when : datetime.datetime
        The date (UTC), within 2010–2029: the model's epochs.
    """
    from pygeomag import GeoMag  # only this lookup needs it

    lat = as_finite_number("latitude_deg", latitude_deg)
    lon = as_finite_number("longitude_deg", longitude_deg)
    alt = as_finite_number("altitude_m", altitude_m)
    if not -90.0 <= lat <= 90.0:
        raise ValueError(f"latitude_deg: expected a latitude in [-90, 90] deg, got {lat!r}")
    if not -180.0 <= lon <= 180.0:
        raise ValueError(f"longitude_deg: expected a longitude in [-180, 180] deg, got {lon!r}")
    if not isinstance(when, datetime.datetime):
        raise TypeError(f"when: expected a datetime.datetime (UTC), got {type(when).__name__}")
    if not _FIRST_YEAR <= when.year < _END_YEAR:
        raise ValueError(f"when: expected a date in {_FIRST_YEAR}–{_END_YEAR - 1} (the World Magnetic Model's "
                         f"epochs), got {when.date().isoformat()}")
    result = GeoMag(base_year=when.year).calculate(glat=lat, glon=lon, alt=alt / 1000.0, time=decimal_year(when))
    return float(np.radians(result.d))
