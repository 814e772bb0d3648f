"""Real sensor data: locating the files (and, later, loading them)."""

from .paths import SOURCES, DataNotFoundError, data_path, search_dirs

__all__ = [
    "DataNotFoundError",
    "SOURCES",
    "data_path",
    "search_dirs",
]
