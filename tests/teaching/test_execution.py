"""The notebook client: it runs cells, reads the chapters' widget cells, and keeps the cell timeout."""

import time

import nbformat
import pytest
from nbclient.exceptions import CellTimeoutError

from quadlib.teaching.execution import notebook_client

SLIDERS = ("from quadlib.teaching.tuning import kf_tuning_trial, tuning_sliders\n"
           "tuning_sliders(kf_tuning_trial, sigma_w=(0.03, 3.0), sigma_r=(0.01, 1.0), true_sigma_w=[0.3, 0.9])")


def _notebook(*sources):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(s) for s in sources]
    return nb


def test_a_widget_cell_and_the_cell_after_it_run(tmp_path):
    nb = _notebook(SLIDERS, "print(6 * 7)")
    notebook_client(nb, tmp_path, timeout_s=60).execute()
    assert any("application/vnd.jupyter.widget-view+json" in o.get("data", {}) for o in nb.cells[0].outputs)
    assert nb.cells[1].outputs[0]["text"] == "42\n"


def test_the_shell_channel_is_read_in_short_waits_however_the_kernel_is_started(tmp_path):
    nb = _notebook("1")
    client = notebook_client(nb, tmp_path, timeout_s=60)
    with client.setup_kernel():  # the mutation run's way; execute() is the grader's
        assert client.kc.shell_channel.get_msg.__qualname__.startswith("_read_in_short_waits")
        client.execute_cell(nb.cells[0], 0)
    assert nb.cells[0].outputs[0]["data"]["text/plain"] == "1"


def test_a_cell_that_outlasts_the_timeout_is_stopped(tmp_path):
    nb = _notebook("import time\ntime.sleep(30)")
    start = time.perf_counter()
    with pytest.raises(CellTimeoutError):
        notebook_client(nb, tmp_path, timeout_s=2).execute()
    assert time.perf_counter() - start < 25


def test_the_folder_must_exist(tmp_path):
    with pytest.raises(NotADirectoryError, match="directory: expected an existing folder"):
        notebook_client(_notebook("1"), tmp_path / "missing")
