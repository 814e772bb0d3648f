"""Keep numba's cache of quadlib's compiled functions in step with their sources, module by module.

numba caches each compiled function next to its module (``__pycache__/<module>.*.nbi``, ``*.nbc``)
and reloads it while that module's file is unchanged; the functions and constants it uses from
other modules are compiled into it, and a change to *their* modules is not noticed. So each module
that uses numba gets a digest of its source and of every quadlib module it imports, transitively
(:func:`module_digest`); :func:`clear_stale` (run when quadlib is imported, by importing this
module) removes the cache of the modules whose digest changed, and only theirs: editing one model
recompiles that model. The engine's per-filter copies (:mod:`quadlib.engine.build`) carry the same
digests in their file names, so they never go stale and are left alone here.
"""

from __future__ import annotations

import ast
import hashlib
import json
from functools import cache
from pathlib import Path

__all__ = ["clear_stale", "module_digest"]

_PACKAGE = Path(__file__).resolve().parent
_STAMP = _PACKAGE / "__pycache__" / "numba-sources.json"


def _sources() -> list[Path]:
    return sorted(p for p in _PACKAGE.rglob("*.py") if "__pycache__" not in p.relative_to(_PACKAGE).parts)


@cache
def _quadlib_imports(path: Path) -> tuple[Path, ...]:
    """The files of the quadlib modules that the module at ``path`` imports."""
    found = set()
    for node in ast.walk(ast.parse(path.read_bytes())):
        names = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        for name in names:
            if name == "quadlib" or name.startswith("quadlib."):
                parts = name.split(".")[1:]
                module, package = _PACKAGE.joinpath(*parts).with_suffix(".py"), _PACKAGE.joinpath(*parts, "__init__.py")
                for candidate in (module, package):
                    if candidate.is_file():
                        found.add(candidate)
    return tuple(sorted(found))


@cache
def module_digest(path: Path) -> str:
    """A hash of a quadlib module's source and of every quadlib module it imports, transitively."""
    digest, seen, todo = hashlib.sha256(), set(), [Path(path).resolve()]
    while todo:
        p = todo.pop()
        if p not in seen:
            seen.add(p)
            todo.extend(_quadlib_imports(p))
    for p in sorted(seen):
        digest.update(str(p.relative_to(_PACKAGE)).encode() + b"\0" + p.read_bytes())
    return digest.hexdigest()


def clear_stale() -> None:
    """Remove the numba cache of each quadlib module whose source, or a source it imports, changed
    since the cache was written."""
    try:
        sources = _sources()
        files = hashlib.sha256(b"".join(str(p).encode() + p.read_bytes() for p in sources)).hexdigest()
        stamps = json.loads(_STAMP.read_text()) if _STAMP.exists() else {}
        if stamps.get("files") == files:  # nothing edited: the usual case, without parsing anything
            return
        module_digest.cache_clear()
        _quadlib_imports.cache_clear()
        digests = {}
        for path in sources:
            if b"from numba import" not in path.read_bytes():
                continue
            key = str(path.relative_to(_PACKAGE))
            digests[key] = module_digest(path)
            if stamps.get("modules", {}).get(key) != digests[key]:
                for cached in path.parent.glob(f"__pycache__/{path.stem}.*.nb[ic]"):
                    cached.unlink(missing_ok=True)
        _STAMP.parent.mkdir(exist_ok=True)
        _STAMP.write_text(json.dumps({"files": files, "modules": digests}))
    except (OSError, ValueError):  # a read-only install (its cache was written by its own build), a torn stamp
        pass


clear_stale()
