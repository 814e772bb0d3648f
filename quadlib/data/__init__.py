"""Real sensor data: locating the files and loading them in the project's conventions."""

from .broad import ENU_TO_NED, BroadTrial, broad_trial_names, gyro_truth_mismatch_deg, load_broad_trial
from .paths import KNOWN_FILES, SOURCES, DataCorruptError, DataNotFoundError, data_path, search_dirs
from .px4 import FlightLog, load_px4_log, load_ulog

__all__ = [
    "BroadTrial",
    "DataCorruptError",
    "DataNotFoundError",
    "ENU_TO_NED",
    "FlightLog",
    "KNOWN_FILES",
    "SOURCES",
    "broad_trial_names",
    "data_path",
    "gyro_truth_mismatch_deg",
    "load_broad_trial",
    "load_px4_log",
    "load_ulog",
    "search_dirs",
]
