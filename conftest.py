"""Shared by every pytest run from the project root (unit tests and nbval): no progress bars,
so that the notebooks' kernels, which inherit this environment, write the stored outputs; and the
groups pytest-xdist keeps on one worker (``--dist loadgroup``, see the Makefile)."""

import pytest

from quadlib.progress import switch_off

switch_off()


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist's own hook reads the groups
def pytest_collection_modifyitems(items):
    """Each test file is one group (a notebook's cells share its kernel; a module's tests share its
    fixtures), unless a test names its own group: then it can run beside the rest of its file."""
    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
