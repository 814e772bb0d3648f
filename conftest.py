"""Shared by every pytest run from the project root (unit tests and nbval): no progress bars,
so that the notebooks' kernels, which inherit this environment, write the stored outputs."""

from quadlib.progress import switch_off

switch_off()
