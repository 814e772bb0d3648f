"""The Euler-rate complementary filter's loop (:func:`quadlib.attitude.complementary.euler_rate_complementary`),
compiled: chapter 10 runs it on long logs and in its sliders, the fixed-wing and 3D comparisons as
a baseline.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.kernels import called_from_python

__all__: list[str] = []  # called by quadlib.attitude.complementary


@called_from_python
@njit(cache=True)
def euler_rate_loop(dt, gyro, tilt, roll, pitch, weight):
    """Roll and pitch ``(N, 2)`` from ``roll, pitch`` at the start: each step turns the gyro's body
    rates into Euler rates with the last estimate (the first two rows of
    :func:`~quadlib.geometry.rotations.euler_rate_matrix`), integrates them, and blends the result with
    the accelerometer's ``tilt`` by ``weight[k]`` on the gyro."""
    out = np.empty((tilt.shape[0], 2))
    out[0, 0], out[0, 1] = roll, pitch
    for k in range(1, tilt.shape[0]):
        p, q, r, a = gyro[k - 1, 0], gyro[k - 1, 1], gyro[k - 1, 2], weight[k]
        sr, cr, tp = math.sin(roll), math.cos(roll), math.tan(pitch)
        roll_rate = p + (sr * q + cr * r) * tp
        pitch_rate = cr * q - sr * r
        roll = a * (roll + dt * roll_rate) + (1.0 - a) * tilt[k, 0]
        pitch = a * (pitch + dt * pitch_rate) + (1.0 - a) * tilt[k, 1]
        out[k, 0], out[k, 1] = roll, pitch
    return out
