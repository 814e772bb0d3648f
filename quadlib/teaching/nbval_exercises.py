"""A pytest plugin for nbval: in nbval's run of a chapter, each exercise's blank answer and listed
wrong answers are tried in the chapter's own kernel, just before its solution cell runs.

Load it with ``-p quadlib.teaching.nbval_exercises`` (the project's root ``conftest.py`` does); a
chapter is then executed once for both its stored outputs and its exercises' checks, where running
:func:`~quadlib.teaching.grading.mutation_run` beside nbval executed it twice.
"""

from __future__ import annotations

from queue import Empty

import pytest

__all__: list[str] = []  # pytest hooks and items


class ExerciseAnswers(pytest.Item):
    """Runs just before an exercise's solution cell, in the chapter's nbval kernel: the student
    edition's blank answer must make the check say "answer not set yet", and each wrong answer listed
    in the solution's metadata must fail the check with feedback
    (:func:`quadlib.teaching.grading.try_answers`; the solution and its check then run as nbval's
    next items, and their outputs are compared as every cell's)."""

    def __init__(self, *, exercise, number, **kwargs):
        super().__init__(**kwargs)
        self.exercise, self.number = exercise, number

    def runtest(self):
        from quadlib.teaching.grading import try_answers

        nb = self.parent.nb
        listed = nb.cells[self.exercise.answer].metadata.get("mutations", [])
        assert len(listed) >= 2, f"exercise {self.number}: list a few plausible wrong answers (found {len(listed)})"
        tried = try_answers(nb, self.exercise, self.number, self._execute)
        accepted = [(m.source, m.feedback) for m in tried if not m.rejected]
        assert not accepted, f"exercise {self.number}: answers the check did not reject as it should: {accepted}"

    def _execute(self, source):
        """Run ``source`` in the notebook's kernel; the name and message of its error, or None."""
        kernel, timeout = self.parent.kernel, self.config.option.nbval_cell_timeout
        msg_id = kernel.execute_cell_input(source, allow_stdin=False)
        try:
            kernel.await_reply(msg_id, timeout=timeout)
        except Empty:
            kernel.interrupt()
            raise TimeoutError(f"exercise {self.number}: an answer tried ran over {timeout} s: {source!r}") from None
        error = None
        while True:
            msg = kernel.get_message("iopub", timeout=timeout)
            if msg["parent_header"].get("msg_id") != msg_id:
                continue
            if msg["msg_type"] == "error" and error is None:
                error = (msg["content"]["ename"], msg["content"]["evalue"])
            if msg["msg_type"] == "status" and msg["content"]["execution_state"] == "idle":
                return error

    def reportinfo(self):
        return self.path, None, f"{self.path.name}::{self.name}"

    def repr_failure(self, excinfo):
        if isinstance(excinfo.value, (AssertionError, TimeoutError)):
            return str(excinfo.value).split("\nassert ")[0]  # the message, without pytest's rewritten expression
        return super().repr_failure(excinfo)


def pytest_collection_modifyitems(session, config, items):
    """Put an :class:`ExerciseAnswers` item before each exercise's solution cell of every notebook
    nbval collects (same notebook, same kernel, same worker under ``--dist loadscope``)."""
    try:
        from nbval.plugin import IPyNbCell
    except ImportError:
        return
    from quadlib.teaching.grading import exercises

    ordered = []
    for item in items:
        if isinstance(item, IPyNbCell):
            nb = item.parent.nb
            for number, ex in enumerate(exercises(nb), start=1):
                if nb.cells[ex.answer] is item.cell:
                    ordered.append(ExerciseAnswers.from_parent(item.parent, name=f"Exercise {number} answers",
                                                               exercise=ex, number=number))
        ordered.append(item)
    items[:] = ordered
