"""Grade one submission with otter's autograder, with a time limit on every cell.

Usage: ``python -m quadlib.teaching.otter_run CELL_TIMEOUT_S AUTOGRADER_ZIP SUBMISSION OUTPUT_DIR``
(:func:`quadlib.teaching.autograde.grade_submission` runs it once per submission, in a process of
its own). It is ``otter run`` with one
change: the notebook's execution (nbconvert's ``ExecutePreprocessor``, which otter uses) stops any
cell after ``CELL_TIMEOUT_S`` seconds by interrupting the kernel, records the interruption as that
cell's error and goes on, so the questions after a cell that loops forever are still graded.
"""

from __future__ import annotations

import sys

import nbconvert.preprocessors
from traitlets import Bool, Int

__all__ = ["TIMEOUT_MARK", "main"]

TIMEOUT_MARK = "cell stopped after"


def main(cell_timeout_s: int, autograder: str, submission: str, output_dir: str) -> None:
    """Run otter's autograder ``autograder`` (a zip) on ``submission``, each cell stopped after
    ``cell_timeout_s`` seconds; otter writes ``results.json`` to ``output_dir``."""
    class TimedExecutePreprocessor(nbconvert.preprocessors.ExecutePreprocessor):
        timeout = Int(cell_timeout_s, allow_none=True).tag(config=True)
        interrupt_on_timeout = Bool(True).tag(config=True)

        async def _async_handle_timeout(self, timeout, cell=None):
            print(f"{TIMEOUT_MARK} {timeout} s", file=sys.stderr, flush=True)  # the grader notes it
            return await super()._async_handle_timeout(timeout, cell)

    nbconvert.preprocessors.ExecutePreprocessor = TimedExecutePreprocessor  # otter imports it when it grades
    from otter.run import main as otter_run

    otter_run(submission, autograder=autograder, output_dir=output_dir, no_logo=True)


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit("usage: python -m quadlib.teaching.otter_run CELL_TIMEOUT_S AUTOGRADER_ZIP SUBMISSION OUTPUT_DIR")
    main(int(sys.argv[1]), *sys.argv[2:])
