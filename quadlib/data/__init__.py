"""Real sensor data: locating the files (and, later, loading them)."""

from .broad import ENU_TO_NED, BroadTrial, broad_trial_names, load_broad_trial
from .paths import KNOWN_FILES, SOURCES, DataCorruptError, DataNotFoundError, data_path, search_dirs

__all__ = [
    "BroadTrial",
    "DataCorruptError",
    "DataNotFoundError",
    "ENU_TO_NED",
    "KNOWN_FILES",
    "SOURCES",
    "broad_trial_names",
    "data_path",
    "load_broad_trial",
    "search_dirs",
]
