import pytest

from quadlib.data import paths as data


def test_missing_file_says_where_to_fetch(monkeypatch, tmp_path):
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    monkeypatch.setattr(data, "PROJECT_ROOT", tmp_path / "project")
    with pytest.raises(data.DataNotFoundError) as info:
        data.data_path("broad/02_undisturbed_slow_rotation_B.hdf5")
    message = str(info.value)
    assert "github.com/dlaidig/broad" in message and str(tmp_path) in message and "QUADLIB_DATA" in message
    assert isinstance(info.value, FileNotFoundError)


def test_env_folder_is_searched_first(monkeypatch, tmp_path):
    (tmp_path / "px4").mkdir()
    (tmp_path / "px4" / "sample.ulg").write_bytes(b"ULog")
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    assert data.data_path("px4/sample.ulg") == tmp_path / "px4" / "sample.ulg"


def test_relative_path_required():
    with pytest.raises(ValueError, match="relative: expected a relative path"):
        data.data_path("/etc/passwd")


def test_shared_data_found_when_present():
    folder = data.PROJECT_ROOT.parent / "shared" / "data"
    if not (folder / "px4" / "sample.ulg").is_file():
        pytest.skip(f"shared data not present at {folder}")
    assert data.data_path("px4/sample.ulg").stat().st_size > 1000
