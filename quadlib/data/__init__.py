"""Real sensor data: locating the files (and, later, loading them)."""

from .paths import KNOWN_FILES, SOURCES, DataCorruptError, DataNotFoundError, data_path, search_dirs

__all__ = [
    "DataCorruptError",
    "DataNotFoundError",
    "KNOWN_FILES",
    "SOURCES",
    "data_path",
    "search_dirs",
]
