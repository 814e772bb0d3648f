"""Shared by every pytest run from the project root (unit tests and nbval): no progress bars,
so that the notebooks' kernels, which inherit this environment, write the stored outputs."""

import os

os.environ["QUADLIB_PROGRESS"] = "off"
