"""numba's cache of a quadlib module is dropped when its source or a source it imports changes, and only then."""

from quadlib import numba_cache


def test_an_edit_clears_the_cache_of_the_modules_it_reaches_and_no_other(tmp_path, monkeypatch):
    (tmp_path / "constants.py").write_text("G = 9.8\n")
    (tmp_path / "linalg.py").write_text("from numba import njit\n")
    (tmp_path / "model.py").write_text("from numba import njit\nfrom quadlib.linalg import f\n"
                                       "from quadlib.constants import G\n")
    (tmp_path / "plain.py").write_text("x = 1\n")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    monkeypatch.setattr(numba_cache, "_PACKAGE", tmp_path)
    monkeypatch.setattr(numba_cache, "_STAMP", cache / "numba-sources.json")

    def compile_both():
        for module in ("linalg", "model"):
            for name in (f"{module}.f-3.py311.nbi", f"{module}.f-3.py311.1.nbc"):
                (cache / name).write_bytes(b"machine code")

    def cached() -> set[str]:
        return {p.name.split(".")[0] for p in cache.glob("*.nb[ic]")}

    numba_cache.clear_stale()  # no stamp yet: whatever is cached may be stale
    compile_both()
    numba_cache.clear_stale()
    assert cached() == {"linalg", "model"}  # nothing changed
    (tmp_path / "plain.py").write_text("x = 2\n")
    numba_cache.clear_stale()
    assert cached() == {"linalg", "model"}  # a module nothing compiled imports
    (tmp_path / "model.py").write_text((tmp_path / "model.py").read_text() + "# edited\n")
    numba_cache.clear_stale()
    assert cached() == {"linalg"}  # the edited module only
    compile_both()
    (tmp_path / "constants.py").write_text("G = 9.81\n")  # a constant numba froze into model's code
    numba_cache.clear_stale()
    assert cached() == {"linalg"}
    compile_both()
    (tmp_path / "linalg.py").write_text("from numba import njit\n# edited\n")
    numba_cache.clear_stale()
    assert not cached()  # linalg and the model that calls it
