"""Keep numba's cache of quadlib's compiled functions in step with their sources.

numba caches each compiled function next to its module (``__pycache__/*.nbi``, ``*.nbc``) and
reloads it while that module's file is unchanged; the functions it calls are compiled into it, and
a change to *their* module is not noticed. The engine's loop calls every model's kernels, so an
edited kernel would leave the engine running the old one. :func:`clear_stale` (run when quadlib
is imported, by importing this module) hashes every module of the package that uses numba and,
when the hash differs from the one stored beside the cache, removes the package's numba cache:
the next call compiles afresh.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

__all__ = ["clear_stale"]

_PACKAGE = Path(__file__).resolve().parent
_STAMP = _PACKAGE / "__pycache__" / "numba-sources.sha256"


def _sources_digest() -> str:
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        text = path.read_bytes()
        if b"from numba import" in text:
            digest.update(str(path.relative_to(_PACKAGE)).encode() + b"\0" + text)
    return digest.hexdigest()


def clear_stale() -> None:
    """Remove quadlib's numba cache if any module that uses numba changed since it was written."""
    try:
        digest = _sources_digest()
        if _STAMP.exists() and _STAMP.read_text() == digest:
            return
        for cached in list(_PACKAGE.rglob("__pycache__/*.nb[ic]")):
            cached.unlink(missing_ok=True)
        _STAMP.parent.mkdir(exist_ok=True)
        _STAMP.write_text(digest)
    except OSError:  # a read-only install: its cache was written by its own build
        pass


clear_stale()
