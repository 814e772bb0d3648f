"""Shared by every pytest run from the project root (unit tests and nbval): no progress bars,
so that the notebooks' kernels, which inherit this environment, write the stored outputs; and, in
nbval's run of each chapter, its exercises' blank and wrong answers tried in the same kernel
(:mod:`quadlib.teaching.nbval_exercises`)."""

from quadlib.progress import switch_off

switch_off()

pytest_plugins = ["quadlib.teaching.nbval_exercises"]
