"""Locate the real sensor data sets (BROAD, PX4 logs) and make sure a file is whole before it is read.

The files are looked up in, in order:

1. the folder named by the environment variable ``QUADLIB_DATA`` (it must exist);
2. ``data/`` inside the project folder, which ships every file the chapters and tests read;
3. ``../shared/data`` next to the project folder (the development layout), for files not shipped.

The project's own ``data/`` comes before ``../shared/data``, so that what the chapters and tests
compute does not depend on whether that folder exists.

A name must stay inside those folders (no ``..``). A file that is not there gives a
:class:`DataNotFoundError`; one that is there but damaged — empty, truncated, not the format its
name says, or, for the files the chapters use, not byte for byte the published one — gives a
:class:`DataCorruptError`. Both say which file, where it was looked for and where to fetch it.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path, PurePosixPath

__all__ = ["KNOWN_FILES", "SOURCES", "DataCorruptError", "DataNotFoundError", "data_path", "search_dirs"]

PROJECT_ROOT = Path(__file__).resolve().parents[2]

SOURCES = {
    "broad": "BROAD data set, folder data_hdf5/ of https://github.com/dlaidig/broad "
             "(Laidig et al., Data 2021, 6(7):72; CC BY 4.0)",
    "px4/01_07_59.px4log": "https://github.com/dronecrew/px4tools, folder test/log/ (BSD-3-Clause)",
    "px4/sample.ulg": "https://github.com/PX4/pyulog, folder test/ (BSD-3-Clause)",
    "px4/sample_px4_events.ulg": "https://github.com/PX4/pyulog, folder test/ (BSD-3-Clause)",
}

KNOWN_FILES = {  # size in bytes and SHA-256 of the published files
    "broad/02_undisturbed_slow_rotation_B.hdf5": (
        3926925, "33ed3432ece89cfbd8c5c069a176106a05dad019302759353244c71d70d7e5f5"),
    "broad/07_undisturbed_fast_rotation_B.hdf5": (
        4080123, "bff6444d38b836482040a328d6060741816ed0150cf2640db94550c6a796b3d8"),
    "broad/09_undisturbed_fast_rotation_with_breaks_B.hdf5": (
        4075108, "40a6e3e69805ba056a53362ca17e75199cc8873aa167b8cf783bb9f71d133f55"),
    "broad/10_undisturbed_slow_translation_A.hdf5": (
        3818653, "bbe80427429f27d0adfffa6720d0b1371a42138290999d1992066e1b9c64ef30"),
    "broad/15_undisturbed_fast_translation_A.hdf5": (
        3890420, "77112d2218c27331ca41eb615450ad9cd67e8385cb0e46e5eda5b5a6d0dd2daf"),
    "broad/16_undisturbed_fast_translation_B.hdf5": (
        3994996, "eebc009755c4fc53c49369a19bae942cf093342a13a51a1ca0eeb23b2cc74abc"),
    "broad/24_disturbed_tapping_A.hdf5": (
        4179383, "6ede0072e95814b561e2c86f8f10fe9f6c79a68a0880d4ca32578fd646ae3bfd"),
    "broad/30_disturbed_stationary_magnet_C.hdf5": (
        3962196, "a4e14a8671c7d0a38c4d41c1883ea2ea471937dfe61ad1bdbee042cea3040808"),
    "broad/32_disturbed_attached_magnet_1cm.hdf5": (
        3335265, "7520dbf2c9844cff6f80e0b7ef1ed93afec08964042ee3d2ee055144379af363"),
    "broad/34_disturbed_attached_magnet_3cm.hdf5": (
        3379630, "f1cc33cf184d06cdbaef3e21ee2bb7ad36d7b1e3ed1098434c22e2c6a3f17f91"),
    "px4/01_07_59.px4log": (
        2913286, "15dc438491dccf1bfe85e8e2a9c38673a2232aa58c277cb2442183d154037c34"),
    "px4/sample.ulg": (
        4053364, "81952e6059bc095717e7911c010e07f85749d6b04d332a5ffc51575a3fd0a558"),
    "px4/sample_px4_events.ulg": (
        1563146, "4b43a23a7b7f649004facba5c7835d800bbc8cc13e71cbc96678d971451e3d7e"),
}

_SIGNATURES = {".hdf5": b"\x89HDF\r\n\x1a\n", ".ulg": b"ULog", ".px4log": b"\xa3\x95"}
_verified: dict[Path, tuple[int, int]] = {}  # path -> (size, mtime) of files already checked in this process


class DataNotFoundError(FileNotFoundError):
    """A data file is not on this machine; the message says where to get it."""


class DataCorruptError(ValueError):
    """A data file is there but damaged (empty, truncated, wrong format or contents)."""


def search_dirs() -> list[Path]:
    """Folders searched for data, in order. A ``QUADLIB_DATA`` that is not a folder is an error."""
    dirs = []
    env = os.environ.get("QUADLIB_DATA")
    if env:
        if not Path(env).is_dir():
            raise DataNotFoundError(f"QUADLIB_DATA: expected a folder holding broad/ and px4/, got {env!r}, "
                                    "which does not exist; fix or unset it")
        dirs.append(Path(env))
    dirs += [PROJECT_ROOT / "data", PROJECT_ROOT.parent / "shared" / "data"]
    return dirs


def _source(relative: str) -> str:
    return next((s for key, s in SOURCES.items() if relative == key or relative.startswith(key + "/")),
                "the public sources listed in the project README")


def _check(path: Path, relative: str) -> None:
    stat = path.stat()
    if _verified.get(path) == (stat.st_size, stat.st_mtime_ns):
        return
    refetch = f"Delete it and fetch it again from {_source(relative)}."
    if stat.st_size == 0:
        raise DataCorruptError(f"data file {str(path)!r} is empty. {refetch}")
    signature = _SIGNATURES.get(path.suffix)
    if signature is not None:
        with path.open("rb") as f:
            head = f.read(len(signature))
        if head != signature:
            raise DataCorruptError(f"data file {str(path)!r} is not a {path.suffix} file (it starts with {head!r}). "
                                   f"{refetch}")
    if relative in KNOWN_FILES:
        size, sha256 = KNOWN_FILES[relative]
        if stat.st_size != size:
            raise DataCorruptError(f"data file {str(path)!r} has {stat.st_size} bytes, the published file {size} "
                                   f"(truncated or altered). {refetch}")
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        if digest != sha256:
            raise DataCorruptError(f"data file {str(path)!r} differs from the published file (SHA-256 {digest[:12]}…, "
                                   f"expected {sha256[:12]}…). {refetch}")
    _verified[path] = (stat.st_size, stat.st_mtime_ns)


def data_path(relative: str | os.PathLike) -> Path:
    """Absolute path of a data file such as ``"broad/02_undisturbed_slow_rotation_B.hdf5"``, checked.

    Raises
    ------
    DataNotFoundError
        With the folders searched and the public source of the file.
    DataCorruptError
        The file is empty, truncated, of the wrong format or not the published one.
    """
    if not isinstance(relative, (str, os.PathLike)) or not str(relative):
        raise TypeError(f"relative: expected a relative path (str or Path) such as 'px4/sample.ulg', got {relative!r}")
    parts = PurePosixPath(Path(relative).as_posix())
    if parts.is_absolute() or Path(relative).is_absolute() or ".." in parts.parts:
        raise ValueError(f"relative: expected a path inside the data folder such as 'px4/sample.ulg', got {relative!r}")
    name = parts.as_posix()
    for d in search_dirs():
        candidate = d / name
        if candidate.is_file():
            _check(candidate, name)
            return candidate
    searched = "\n".join(f"  - {d}" for d in search_dirs())
    raise DataNotFoundError(
        f"data file {name!r} not found. Searched:\n{searched}\n"
        f"Fetch it from {_source(name)} and put it under one of these folders "
        f"(or point QUADLIB_DATA at the folder that holds it)."
    )
