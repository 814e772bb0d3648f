"""BROAD trials (Laidig et al., *Data* 2021, 6(7):72; CC BY 4.0) in the project's conventions.

A BROAD file holds a sensor's gyro (rad/s), accelerometer (m/s²) and magnetometer (µT) at
285.7 Hz, the optical ground truth ``opt_quat`` (the sensor's orientation in an East-North-Up
earth frame, scalar first), ``opt_pos`` and the ``movement`` mask of the samples that count.

Conversion (:func:`load_broad_trial`):

* earth frame ENU → NED: ``v_ned = C v_enu`` with ``C = [[0, 1, 0], [1, 0, 0], [0, 0, −1]]``
  (swap east and north, flip up), a rotation by 180° about (1, 1, 0)/√2, so
  ``q_nb = q_C ⊗ q_enu`` with ``q_C = [0, 1/√2, 1/√2, 0]``;
* the sensor frame is BROAD's own sensor axes (the IMU has no "forward"): ``q_nb`` rotates
  sensor vectors into NED, and a sensor lying flat, z up, reads ``+g`` on z. On a vehicle, mount
  the IMU with its axes forward-right-down to get the FRD body frame of the other chapters;
* the IMU streams stay in the sensor frame, in their units; ground-truth rows where the optical
  markers were hidden are NaN, as in the file;
* gyro timing: a BROAD gyro sample, like any IMU's output, describes the motion *before* its
  timestamp — the sample at ``t[k]`` is the rate over ``(t[k−1], t[k]]`` (VQF, BROAD's reference
  filter, integrates each gyro sample before it uses the accelerometer sample of the same time).
  An :class:`~quadlib.imu.ImuLog` holds ``gyro[k]`` over ``[t[k], t[k+1])``, so the loader moves
  every gyro sample one row earlier: ``gyro[k] = imu_gyr[k+1]``; the last row, the rate after the
  log ends, is NaN. Kept where it was, each rate would be applied one sample late — a 4° lag at the
  1200 °/s of the fast trials. (The optical truth agrees: integrated over ten samples, the moved
  gyro matches its rotations 2.3× better than the unmoved one on the fast-rotation trial,
  ``tests/data/test_broad.py``.)

The benchmark's error metric is :func:`quadlib.analysis.broad_errors`.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import NamedTuple

import numpy as np

from quadlib.data.paths import PROJECT_ROOT, DataCorruptError, data_path
from quadlib.geometry.quaternion import quat_conjugate, quat_multiply, quat_to_rotvec
from quadlib.imu import ImuLog, rates_to_interval_start
from quadlib.validation import as_count

__all__ = ["ENU_TO_NED", "BroadTrial", "broad_trial_names", "gyro_truth_mismatch_deg", "load_broad_trial"]

ENU_TO_NED = np.array([0.0, np.sqrt(0.5), np.sqrt(0.5), 0.0])
"""``q_C``: the rotation that takes ENU coordinates to NED (180° about the east-north bisector)."""


class BroadTrial(NamedTuple):
    """One BROAD trial in the project's conventions.

    Attributes
    ----------
    name : str
        The trial's name, e.g. ``"02_undisturbed_slow_rotation_B"``.
    log : ImuLog
        Gyro [rad/s], accelerometer [m/s²] and magnetometer [µT] in the sensor frame.
    q_nb : (N, 4) ndarray
        Optical ground truth, sensor → NED, scalar first; NaN rows where the markers were hidden.
    movement : (N,) bool ndarray
        The samples the benchmark's errors are computed over.
    position_m : (N, 3) ndarray
        Optical position of the sensor in NED [m] (NaN where hidden).
    info : dict
        The trial's entry in ``trials.json`` (its groups: undisturbed or disturbed, motion, speed …).
    """

    name: str
    log: ImuLog
    q_nb: np.ndarray
    movement: np.ndarray
    position_m: np.ndarray
    info: dict


def broad_trial_names() -> list[str]:
    """Names of the BROAD trials the project ships in its own ``data/broad/``, sorted.

    These are the trials the chapters and benchmarks score. The list is the project's, not the
    machine's: trials in ``QUADLIB_DATA`` or ``../shared/data`` can be loaded by name but are not
    listed, so that a table computed over the list does not depend on what else is installed.
    """
    return sorted(p.stem for p in (PROJECT_ROOT / "data" / "broad").glob("*.hdf5"))


def load_broad_trial(trial: str | os.PathLike) -> BroadTrial:
    """Read one BROAD trial, by name (``"02_undisturbed_slow_rotation_B"``) or path, and convert it.

    A name is looked up with :func:`quadlib.data.data_path` (which also checks the file against the
    published one); a path is read as given. Conversions: see the module's documentation.
    """
    import h5py  # only the loaders need it

    if not isinstance(trial, (str, os.PathLike)):
        raise TypeError(f"trial: expected a trial name or a path, got {type(trial).__name__}")
    path = Path(trial)
    if path.suffix != ".hdf5":
        path = data_path(f"broad/{path.name}.hdf5")
    elif not path.is_file():
        path = data_path(f"broad/{path.name}")
    try:
        with h5py.File(path, "r") as f:
            rate = float(f.attrs["sampling_rate"])
            gyr, acc, mag = (np.asarray(f[k], dtype=float) for k in ("imu_gyr", "imu_acc", "imu_mag"))
            q_enu, pos_enu = np.asarray(f["opt_quat"], dtype=float), np.asarray(f["opt_pos"], dtype=float)
            movement = np.asarray(f["movement"], dtype=bool)
    except (OSError, KeyError) as err:
        raise DataCorruptError(f"data file {str(path)!r} is not a readable BROAD trial ({err}); fetch it again from "
                               "https://github.com/dlaidig/broad, folder data_hdf5/") from err
    n = gyr.shape[0]
    for name, arr, width in (("imu_acc", acc, 3), ("imu_mag", mag, 3), ("opt_quat", q_enu, 4), ("opt_pos", pos_enu, 3)):
        if arr.shape != (n, width):
            raise DataCorruptError(f"data file {str(path)!r}: expected {name} of shape ({n}, {width}), got {arr.shape}")
    info = {}
    trials_json = path.parent / "trials.json"
    if trials_json.is_file():
        info = json.loads(trials_json.read_text()).get("trials", {}).get(path.stem, {})
    c = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
    q_nb = quat_multiply(ENU_TO_NED, np.where(np.isnan(q_enu), 0.0, q_enu))
    q_nb[np.isnan(q_enu).any(axis=1)] = np.nan
    t = np.arange(n) / rate
    gyr = rates_to_interval_start(gyr)  # see the module's notes
    return BroadTrial(name=path.stem, log=ImuLog(t, gyr, acc, mag), q_nb=q_nb, movement=movement,
                      position_m=pos_enu @ c.T, info=info)


def gyro_truth_mismatch_deg(trial: BroadTrial, shift: int = 0, samples: int = 10) -> float:
    """How well the gyro's timing agrees with the optical truth [deg, RMS].

    For every scored sample ``k`` where both truth rows are there, the truth's turn over
    ``[t[k], t[k+samples]]`` (a rotation vector, in the sensor frame) is compared with the gyro's,
    ``Σ gyro[k+shift .. k+shift+samples−1] Δt``. ``shift = 0`` is the loader's timing (``gyro[k]``
    over ``[t[k], t[k+1])``); ``shift = −1`` uses each rate one sample late, as the file's rows
    would be; ``shift = 1`` one sample early. Over ten samples the gyro's noise averages out and
    what remains is mostly timing (and the truth's own noise).
    """
    if not isinstance(trial, BroadTrial):
        raise TypeError(f"trial: expected a BroadTrial, got {type(trial).__name__}")
    shift = as_count("shift", shift, low=-100, high=100)
    m = as_count("samples", samples)
    q, dt, n = trial.q_nb, float(np.median(trial.log.dt)), len(trial.log)
    k = np.arange(max(0, -shift), n - m - max(0, shift))
    k = k[~np.isnan(q[k, 0]) & ~np.isnan(q[k + m, 0]) & trial.movement[k]]
    if k.size == 0:
        raise ValueError(f"trial: expected scored samples with truth {m} samples apart, got none")
    turn = quat_to_rotvec(quat_multiply(quat_conjugate(q[k]), q[k + m]))
    summed = np.cumsum(np.vstack([np.zeros(3), np.nan_to_num(trial.log.gyro)]), axis=0) * dt
    gyro_turn = summed[k + shift + m] - summed[k + shift]
    return float(np.degrees(np.sqrt(np.mean(np.sum((turn - gyro_turn) ** 2, axis=1)))))
