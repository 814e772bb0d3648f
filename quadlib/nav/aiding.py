"""Scan matching as a measurement of the inertial navigation filter.

:func:`~quadlib.perception.scan_to_map` gives the sensor's pose on the map — north, east and yaw —
with an information matrix that changes from scan to scan: large where walls face every way, zero
along a corridor. A :class:`~quadlib.Sensor` has one noise covariance, so each sample is
*whitened*: with ``W = Λ^{1/2}`` (the symmetric square root of the sample's information ``Λ``),
``W z = W h(x) + W v`` has noise of covariance ``W Λ⁻¹ W = I``. The filter is given ``z̃ = W z``,
``h̃(x) = W h(x)`` and ``R = I``; the update is the same as with ``R = Λ⁻¹``, and a direction of zero
information gets a zero row: the filter learns nothing there, as it should, where ``Λ⁻¹`` would not
exist. The χ² gate is unchanged (the NIS does not depend on the whitening).

The yaw is the body x axis's heading, ``ψ = atan2(R₁₀, R₀₀)``. So that an innovation never jumps by
2π, ``h̃`` takes the state's yaw within π of the measured one (which rides along as context), and
its Jacobian is the heading's about the vertical (as :func:`~quadlib.attitude.heading_sensor`).
The lidar is taken to scan the horizontal plane: tilted by a few degrees, it sees walls at
1/cos(tilt) of their distance, a centimetre at 5 m and 4°, left out here.
"""

from __future__ import annotations

import numpy as np

from quadlib.kernels.quaternion import dcm, rate_matrix
from quadlib.model import Sensor
from quadlib.perception.map_matching import MapMatch
from quadlib.samples import Measurements
from quadlib.validation import as_finite_array, as_instance

__all__ = ["ins_pose_sensor", "pose_measurements"]

_CONTEXT = ("yaw [rad]",) + tuple(f"W{i}{j}" for i in range(3) for j in range(3))


def _pose(x, c):
    R = dcm(x[:4])
    yaw = np.arctan2(R[1, 0], R[0, 0])
    yaw = c[0] + (yaw - c[0] + np.pi) % (2.0 * np.pi) - np.pi
    return c[1:].reshape(3, 3) @ np.array([x[7], x[8], yaw])


def _pose_jacobian(x, c):
    J = np.zeros((3, 16))
    J[0, 7] = J[1, 8] = 1.0
    J[2, :4] = dcm(x[:4])[2] @ (2.0 * rate_matrix(x[:4]).T)
    return c[1:].reshape(3, 3) @ J


def ins_pose_sensor(reset_after_s: float | None = None) -> Sensor:
    """The whitened pose ``W [p_n, p_e, ψ]`` (module documentation) for the 16-state INS; build its
    samples with :func:`pose_measurements`."""
    return Sensor(name="scan match", measurement_names=("W·north", "W·east", "W·yaw"), context_names=_CONTEXT,
                  h=_pose, H=_pose_jacobian, R=np.eye(3), reset_after_s=reset_after_s)


def pose_measurements(t, matches, sensor: Sensor | None = None) -> Measurements:
    """Samples of :func:`ins_pose_sensor` from scan matches at times ``t`` (K,): each
    :class:`~quadlib.perception.MapMatch` whitened by its information; ``None`` is a missing sample."""
    t = as_finite_array("t", t, ndim=1)
    try:
        matches = list(matches)
    except TypeError as err:
        raise TypeError(f"matches: expected a sequence of MapMatch or None, got {matches!r:.60}") from err
    if len(matches) != t.size:
        raise ValueError(f"matches: expected one per time ({t.size}), got {len(matches)}")
    z, context = np.full((t.size, 3), np.nan), np.full((t.size, 10), np.nan)
    for j, m in enumerate(matches):
        if m is None:
            continue
        if not isinstance(m, MapMatch):
            raise TypeError(f"matches[{j}]: expected a MapMatch or None, got {type(m).__name__}")
        values, vectors = np.linalg.eigh(0.5 * (m.information + m.information.T))
        W = vectors @ np.diag(np.sqrt(np.clip(values, 0.0, None))) @ vectors.T
        z[j], context[j] = W @ m.pose, np.concatenate([[m.pose[2]], W.ravel()])
    sensor = ins_pose_sensor() if sensor is None else as_instance("sensor", sensor, Sensor)
    return Measurements(sensor, t, z, context=context)
