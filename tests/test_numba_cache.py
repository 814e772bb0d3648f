"""numba's cache of the package is dropped when a module that uses numba changes, and only then."""

from quadlib import numba_cache


def test_an_edited_numba_module_clears_the_cache_and_nothing_else_does(tmp_path, monkeypatch):
    (tmp_path / "kernels.py").write_text("from numba import njit\n")
    (tmp_path / "plain.py").write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    monkeypatch.setattr(numba_cache, "_PACKAGE", tmp_path)
    monkeypatch.setattr(numba_cache, "_STAMP", cache / "numba-sources.sha256")

    def compiled():
        for name in ("kernels.f-3.py311.nbi", "kernels.f-3.py311.1.nbc"):
            (cache / name).write_bytes(b"machine code")

    numba_cache.clear_stale()  # no stamp yet: whatever is cached may be stale
    compiled()
    numba_cache.clear_stale()
    assert len(list(cache.glob("*.nb[ic]"))) == 2  # nothing changed
    (tmp_path / "plain.py").write_text("x = 2\n")
    numba_cache.clear_stale()
    assert len(list(cache.glob("*.nb[ic]"))) == 2  # a module without numba changed
    (tmp_path / "kernels.py").write_text("from numba import njit\n# edited\n")
    numba_cache.clear_stale()
    assert not list(cache.glob("*.nb[ic]"))
