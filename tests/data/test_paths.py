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
    (tmp_path / "px4" / "flight.ulg").write_bytes(b"ULog\x01\x12\x35" + b"\0" * 64)
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    assert data.data_path("px4/flight.ulg") == tmp_path / "px4" / "flight.ulg"


def test_relative_path_required():
    with pytest.raises(ValueError, match="relative: expected a path inside the data folder"):
        data.data_path("/etc/passwd")


def test_shared_data_found_when_present():
    folder = data.PROJECT_ROOT.parent / "shared" / "data"
    if not (folder / "px4" / "sample.ulg").is_file():
        pytest.skip(f"shared data not present at {folder}")
    assert data.data_path("px4/sample.ulg").stat().st_size > 1000


def test_paths_stay_inside_the_data_folder_and_path_objects_work(monkeypatch, tmp_path):
    from pathlib import Path

    (tmp_path / "px4").mkdir()
    (tmp_path / "px4" / "other.ulg").write_bytes(b"ULog\x01\x12\x35" + b"\0" * 64)
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    assert data.data_path(Path("px4") / "other.ulg") == tmp_path / "px4" / "other.ulg"
    with pytest.raises(ValueError, match="relative: expected a path inside the data folder"):
        data.data_path("px4/../../../etc/passwd")
    with pytest.raises(TypeError, match="relative: expected a relative path"):
        data.data_path(3)


def test_a_wrong_quadlib_data_is_an_error(monkeypatch, tmp_path):
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path / "nowhere"))
    with pytest.raises(data.DataNotFoundError, match="QUADLIB_DATA: expected a folder .* which does not exist"):
        data.data_path("px4/sample.ulg")


@pytest.mark.parametrize(("content", "message"), [
    (b"", "is empty"),
    (b"<html>not found</html>", r"is not a \.hdf5 file"),
    (b"\x89HDF\r\n\x1a\n" + b"\0" * 100, "has 108 bytes, the published file 3926925"),
])
def test_a_damaged_file_is_named_with_where_to_fetch_it(monkeypatch, tmp_path, content, message):
    (tmp_path / "broad").mkdir()
    (tmp_path / "broad" / "02_undisturbed_slow_rotation_B.hdf5").write_bytes(content)
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    with pytest.raises(data.DataCorruptError, match=message) as info:
        data.data_path("broad/02_undisturbed_slow_rotation_B.hdf5")
    assert "github.com/dlaidig/broad" in str(info.value) and str(tmp_path) in str(info.value)


def test_same_size_but_altered_contents_are_caught(monkeypatch, tmp_path):
    size = data.KNOWN_FILES["px4/sample.ulg"][0]
    (tmp_path / "px4").mkdir()
    (tmp_path / "px4" / "sample.ulg").write_bytes(b"ULog" + b"\0" * (size - 4))
    monkeypatch.setenv("QUADLIB_DATA", str(tmp_path))
    with pytest.raises(data.DataCorruptError, match="differs from the published file"):
        data.data_path("px4/sample.ulg")


def test_every_shared_file_is_the_published_one():
    folder = data.PROJECT_ROOT.parent / "shared" / "data"
    if not folder.is_dir():
        pytest.skip(f"shared data not present at {folder}")
    for name in data.KNOWN_FILES:
        assert data.data_path(name).is_file()
