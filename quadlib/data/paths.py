"""Locate the real sensor data sets (BROAD, PX4 logs) without crashing when they are absent.

The files are not part of the repository. They are looked up in, in order:

1. the folder named by the environment variable ``QUADLIB_DATA``;
2. ``../shared/data`` next to the project folder (the development and CI layout);
3. ``data/`` inside the project folder.

If none holds the file, :class:`DataNotFoundError` says which file is
missing, where it was looked for, and where to fetch it.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["DataNotFoundError", "SOURCES", "data_path", "search_dirs"]

PROJECT_ROOT = Path(__file__).resolve().parents[2]

SOURCES = {
    "broad": "BROAD data set, folder data_hdf5/ of https://github.com/dlaidig/broad "
             "(Laidig et al., Data 2021, 6(7):72; CC BY 4.0)",
    "px4/01_07_59.px4log": "https://github.com/dronecrew/px4tools, folder test/log/ (BSD-3-Clause)",
    "px4/sample.ulg": "https://github.com/PX4/pyulog, folder test/ (BSD-3-Clause)",
}


class DataNotFoundError(FileNotFoundError):
    """A data file is not on this machine; the message says where to get it."""


def search_dirs() -> list[Path]:
    """Folders searched for data, in order."""
    dirs = []
    if os.environ.get("QUADLIB_DATA"):
        dirs.append(Path(os.environ["QUADLIB_DATA"]))
    dirs += [PROJECT_ROOT.parent / "shared" / "data", PROJECT_ROOT / "data"]
    return dirs


def data_path(relative: str) -> Path:
    """Absolute path of a data file such as ``"broad/02_undisturbed_slow_rotation_B.hdf5"``.

    Raises
    ------
    DataNotFoundError
        With the folders searched and the public source of the file.
    """
    if not isinstance(relative, str) or not relative or Path(relative).is_absolute():
        raise ValueError(f"relative: expected a relative path such as 'px4/sample.ulg', got {relative!r}")
    for d in search_dirs():
        candidate = d / relative
        if candidate.is_file():
            return candidate
    source = next((s for key, s in SOURCES.items() if relative == key or relative.startswith(key + "/")),
                  "the public sources listed in the project README")
    searched = "\n".join(f"  - {d}" for d in search_dirs())
    raise DataNotFoundError(
        f"data file {relative!r} not found. Searched:\n{searched}\n"
        f"Fetch it from {source} and put it under one of these folders "
        f"(or point QUADLIB_DATA at the folder that holds it)."
    )
